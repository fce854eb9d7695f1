//! `tcb view`: one self-contained HTML page that plays a clip on its
//! skeleton, with the curves of a picked joint under it.
//!
//! ```text
//! page.html = page.html's markup
//!           + page.css
//!           + three.min.js   three.js (MIT, its licence at the top), bundled by
//!                            tools/view/bundle.mjs and committed: no node to build
//!           + JSON           frame times, model-space joint positions per frame
//!                            (SkeletonBinding; and the rotations of animated leaf
//!                            joints, which no position shows), one `tcb plot` SVG
//!                            per joint
//!           + page.js        draws the positions, interpolating linearly between frames
//! ```
//!
//! The page computes no animation: what it shows at a frame's time is what
//! the runtime gave, so that a bug in it cannot pass for one in the runtime.

mod plots;
mod poses;

use serde::Serialize;
use std::sync::Arc;
use tcb_core::SourceClip;
use tcb_core::skeleton::Skeleton;

const TEMPLATE: &str = include_str!("page.html");
const STYLE: &str = include_str!("page.css");
const SCRIPT: &str = include_str!("page.js");
const THREE: &str = include_str!("three.min.js");

/// What a page shows besides the clip.
pub(crate) struct Options {
    /// The page's title (the clip file's name).
    pub title: String,
    /// Frames per second of the poses (default: the clip's own).
    pub fps: Option<f64>,
    /// The joint or group of tracks whose curves show first.
    pub joint: Option<String>,
}

/// A page and what the user should know about it.
pub(crate) struct Page {
    /// The HTML document.
    pub html: String,
    /// One line each, for stderr.
    pub notes: Vec<String>,
    /// What the page holds, in one line.
    pub summary: String,
}

/// The JSON the page reads (`#tcb-data`).
#[derive(Serialize)]
struct Data<'a> {
    title: &'a str,
    clip: &'a str,
    version: &'a str,
    times: &'a [f64],
    fps: f64,
    rate: &'a str,
    figure: Option<poses::Figure>,
    groups: Vec<plots::Group>,
    joint: Option<&'a str>,
}

/// The page of `clip` played by `runtime` (`clip` compiled, or the packed
/// stream whose reference it is) on `skeleton` (none: its curves alone).
pub(crate) fn page(
    clip: &SourceClip,
    skeleton: Option<&Skeleton>,
    runtime: Arc<tcb_runtime::Clip>,
    options: &Options,
) -> Result<Page, Box<dyn std::error::Error>> {
    let frames = poses::frames(clip, options.fps)?;
    let groups = plots::groups(clip, skeleton);
    let joint = match &options.joint {
        Some(j) => Some(known_joint(j, skeleton, &groups)?),
        None => None,
    };
    let figure = match skeleton {
        Some(s) => Some(poses::figure(clip, runtime, s, &frames.times)?),
        None => None,
    };
    let (groups, notes) = plots::plots(clip, groups, &options.title)?;
    let summary = format!(
        "{}, {} frames at {} fps ({}), {} tracks in {} plots",
        figure
            .as_ref()
            .map_or("no skeleton (the curves alone)".into(), |f| {
                format!("{} joints", f.names.len())
            }),
        frames.times.len(),
        (frames.fps * 1e4).round() / 1e4,
        frames.source,
        clip.tracks().len(),
        groups.len()
    );
    let data = Data {
        title: &options.title,
        clip: clip.name(),
        version: env!("CARGO_PKG_VERSION"),
        times: &frames.times,
        fps: frames.fps,
        rate: frames.source,
        figure,
        groups,
        joint,
    };
    let json = serde_json::to_string(&data)?;
    Ok(Page {
        html: html(&json),
        notes,
        summary,
    })
}

/// `name` if it is a joint of `skeleton` or a group of tracks.
fn known_joint<'a>(
    name: &'a str,
    skeleton: Option<&Skeleton>,
    groups: &[(String, Vec<String>)],
) -> Result<&'a str, String> {
    if skeleton.is_some_and(|s| s.joint(name).is_some()) || groups.iter().any(|g| g.0 == name) {
        return Ok(name);
    }
    let some: Vec<&str> = groups.iter().take(8).map(|g| g.0.as_str()).collect();
    Err(format!(
        "--joint {name}: no joint or group of tracks of that name (the clip's: {}{})",
        some.join(", "),
        if groups.len() > some.len() {
            ", ..."
        } else {
            ""
        }
    ))
}

/// The page: the template with its style, three.js, the data and the
/// script in place. `</` in the JSON is written `<\/` (the same string to
/// a JSON reader), so no name or SVG in it can end its `<script>`.
fn html(json: &str) -> String {
    let json = json.replace("</", "<\\/");
    let parts = [
        ("/*@style@*/", STYLE),
        ("/*@three@*/", THREE),
        ("/*@data@*/", json.as_str()),
        ("/*@script@*/", SCRIPT),
    ];
    let mut out =
        String::with_capacity(TEMPLATE.len() + parts.iter().map(|p| p.1.len()).sum::<usize>());
    let mut rest = TEMPLATE;
    for (marker, text) in parts {
        let (before, after) = rest
            .split_once(marker)
            .expect("page.html holds each marker once, in order");
        out.push_str(before);
        out.push_str(text);
        rest = after;
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_holds_its_parts_and_no_early_script_end() {
        let clip = tcb_io::ClipDoc::parse(
            r#"{"format": "tcb-clip/1", "tracks": [
              {"name": "</script><b>.x", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#,
        )
        .unwrap()
        .build()
        .unwrap();
        let options = Options {
            title: "t".into(),
            fps: None,
            joint: None,
        };
        let runtime = Arc::new(tcb_runtime::Clip::compile(&clip));
        let page = page(&clip, None, runtime, &options).unwrap();
        // three.js's, the data's and the page script's.
        assert_eq!(page.html.matches("</script").count(), 3);
        assert!(page.html.contains("Permission is hereby granted"));
        assert!(!page.html.contains("/*@"));
        assert!(page.summary.starts_with("no skeleton"), "{}", page.summary);
    }

    #[test]
    fn an_unknown_joint_is_named() {
        let groups = vec![("Hips".to_string(), vec!["Hips.rotation".to_string()])];
        let e = known_joint("Hip", None, &groups).unwrap_err();
        assert_eq!(
            e,
            "--joint Hip: no joint or group of tracks of that name (the clip's: Hips)"
        );
    }
}
