//! The curves under the figure: one `tcb plot` SVG per joint (its
//! translation, rotation and scale tracks), and for tracks of no joint one
//! per name before the last dot (`ball.position` and `ball.squash` are
//! `ball`).

use rayon::prelude::*;
use serde::Serialize;
use tcb_core::SourceClip;
use tcb_core::skeleton::Skeleton;

/// Most plots one page holds (a group past these is left out, and named
/// on stderr).
pub(crate) const MAX_PLOTS: usize = 256;

/// One group's plot, as the page reads it.
#[derive(Serialize)]
pub(crate) struct Group {
    /// The joint, or the tracks' common prefix.
    pub name: String,
    /// Its tracks, in clip order.
    pub tracks: Vec<String>,
    /// `tcb plot CLIP --track ... --from FROM --to TO`, drawn.
    pub svg: String,
    /// The plot's time range, seconds (the page puts a cursor on it).
    pub from: f64,
    /// End of the time range.
    pub to: f64,
}

/// The groups of `clip`'s tracks, in the order of their first track: a
/// joint of `skeleton` for `<joint>.translation|rotation|scale`, else the
/// name up to its last dot (the whole name without one).
pub(crate) fn groups(clip: &SourceClip, skeleton: Option<&Skeleton>) -> Vec<(String, Vec<String>)> {
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for t in clip.tracks() {
        let split = t.name.rsplit_once('.');
        let joint = split
            .filter(|(j, part)| {
                matches!(*part, "translation" | "rotation" | "scale")
                    && skeleton.is_some_and(|s| s.joint(j).is_some())
            })
            .map(|(j, _)| j);
        let name = joint.or(split.map(|(prefix, _)| prefix)).unwrap_or(&t.name);
        match groups.iter_mut().find(|(n, _)| n == name) {
            Some((_, tracks)) => tracks.push(t.name.clone()),
            None => groups.push((name.to_string(), vec![t.name.clone()])),
        }
    }
    groups
}

/// The time range every plot shares: `tcb plot`'s default for the whole
/// clip (the keys' range, 15% wider each side; a second each side of a
/// single key time).
pub(crate) fn time_range(clip: &SourceClip) -> Option<(f64, f64)> {
    let (first, last) = clip.time_range()?;
    let margin = if last > first {
        0.15 * (last - first)
    } else {
        1.0
    };
    Some((first - margin, last + margin))
}

/// Each group of `groups` drawn as `tcb plot` draws it, titled `title`
/// (at most [`MAX_PLOTS`]), and the notes for the user: tcb-plot's, and the
/// groups left out.
pub(crate) fn plots(
    clip: &SourceClip,
    groups: Vec<(String, Vec<String>)>,
    title: &str,
) -> Result<(Vec<Group>, Vec<String>), tcb_plot::PlotError> {
    let Some((from, to)) = time_range(clip) else {
        return Ok((Vec::new(), Vec::new()));
    };
    let mut notes = Vec::new();
    if groups.len() > MAX_PLOTS {
        let left: Vec<&str> = groups[MAX_PLOTS..].iter().map(|g| g.0.as_str()).collect();
        notes.push(format!(
            "{} groups of tracks past the first {MAX_PLOTS} have no plot: {}",
            left.len(),
            left.join(", ")
        ));
    }
    let drawn = groups
        .into_par_iter()
        .take(MAX_PLOTS)
        .map(|(name, tracks)| {
            let plot = tcb_plot::Plot {
                tracks: tracks.clone(),
                from: Some(from),
                to: Some(to),
                ..tcb_plot::Plot::new(title)
            };
            let r = tcb_plot::render_with_notes(clip, &plot)?;
            let group = Group {
                name,
                tracks,
                svg: without_repeated_points(&r.svg),
                from,
                to,
            };
            Ok((group, r.notes))
        })
        .collect::<Result<Vec<_>, tcb_plot::PlotError>>()?;
    let mut out = Vec::with_capacity(drawn.len());
    for (group, n) in drawn {
        notes.extend(n);
        out.push(group);
    }
    Ok((out, notes))
}

/// `svg` with each polyline's runs of one point written once: the same
/// picture. Curves are sampled at every key and drawn on whole pixels, so
/// a capture's curves repeat most points (half the bytes of its plots).
/// Text cannot hold the attribute: plotters writes its quotes `&quot;`.
fn without_repeated_points(svg: &str) -> String {
    const POINTS: &str = " points=\"";
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(at) = rest.find(POINTS) {
        let (before, after) = rest.split_at(at + POINTS.len());
        out.push_str(before);
        let end = after.find('"').unwrap_or(after.len());
        let mut last = None;
        for (i, p) in after[..end].split_ascii_whitespace().enumerate() {
            if last != Some(p) {
                if i > 0 {
                    out.push(' ');
                }
                out.push_str(p);
            }
            last = Some(p);
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_points_go_and_the_rest_stays() {
        let svg = r#"<svg><polyline stroke="black" points="1,2 1,2 1,2 3,4 1,2 1,2 "/><text x="1">a points=&quot;x x&quot;</text><polyline points="5,5"/></svg>"#;
        assert_eq!(
            without_repeated_points(svg),
            r#"<svg><polyline stroke="black" points="1,2 3,4 1,2"/><text x="1">a points=&quot;x x&quot;</text><polyline points="5,5"/></svg>"#
        );
    }

    #[test]
    fn tracks_group_by_joint_or_by_prefix() {
        let clip = tcb_io::ClipDoc::parse(
            r#"{"format": "tcb-clip/1", "tracks": [
              {"name": "a.b.rotation", "kind": "quat", "times": [0, 1], "values": [[0, 0, 0, 1], [0, 0, 0, 1]]},
              {"name": "ball.position", "kind": "vec2", "times": [0, 1], "values": [[0, 0], [1, 1]]},
              {"name": "a.b.translation", "kind": "vec3", "times": [0, 1], "values": [[0, 0, 0], [1, 1, 1]]},
              {"name": "ball.squash", "kind": "scalar", "times": [0, 1], "values": [0, 1]},
              {"name": "alone", "kind": "scalar", "times": [0, 1], "values": [0, 1]}]}"#,
        )
        .unwrap()
        .build()
        .unwrap();
        let g = groups(&clip, None);
        let names: Vec<&str> = g.iter().map(|g| g.0.as_str()).collect();
        assert_eq!(names, ["a.b", "ball", "alone"]);
        assert_eq!(g[1].1, ["ball.position", "ball.squash"]);
        let (plots, notes) = plots(&clip, g, "t").unwrap();
        assert_eq!(plots.len(), 3);
        assert!(notes.is_empty(), "{notes:?}");
        assert!(plots[1].svg.contains("ball.position") && plots[1].svg.contains("ball.squash"));
        assert_eq!((plots[0].from, plots[0].to), (-0.15, 1.15));
    }
}
