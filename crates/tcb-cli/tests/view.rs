//! `tcb view`: the page it writes and its errors, and that page in headless
//! Chromium (`tools/view/check.mjs`): the figure where `SkeletonBinding`
//! puts it, the screenshots moving as the motion does, the controls, and a
//! clip with no skeleton shown as its curves alone.
//!
//! The browser tests need node, `npm ci --prefix tools/view` and Chromium
//! (`CHROMIUM`, default /usr/bin/chromium). Without them they are skipped
//! with a note, unless `CI` is set: `.ci/run` installs them, and there a
//! missing browser is a failure. Their screenshots stay in
//! `target/tmp/view-shots/` to be looked at.

mod common;

use common::*;
use serde::Deserialize;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

#[test]
fn view_writes_one_self_contained_page() {
    let dir = scratch("view-page");
    let out = dir.join("cmu.html");
    let o = tcb_to("view", file("data/cmu-01_01.bvh"), &out, &[]);
    assert_success(&o);
    stderr_has(
        &o,
        "38 joints, 2752 frames at 120.0005 fps (the clip's key times), 32 tracks in 31 plots",
    );
    let html = std::fs::read_to_string(&out).unwrap();
    // three.js inside, with its licence; nothing fetched.
    assert!(html.contains("three.js r187") && html.contains("Permission is hereby granted"));
    assert!(!html.contains("<script src") && !html.contains("<link"));
    assert_eq!(html.matches("</script>").count(), 3);

    // Without -o: the clip's name with .html, in the current folder.
    let o = command()
        .current_dir(&dir)
        .args(["view", &file("examples/clips/bounce.json")])
        .output()
        .unwrap();
    assert_success(&o);
    stderr_has(
        &o,
        "no skeleton (the curves alone), 121 frames at 60 fps (the default: keys not evenly spaced), 3 tracks in 1 plots",
    );
    assert!(dir.join("bounce.html").is_file());

    // A packed clip keeps its input's skeleton and plays its own stream.
    let packed = dir.join("cmu.tcbc");
    let short = short_cmu(120);
    let o = tcb_to("compress", &short, &packed, &[]);
    assert_success(&o);
    let o = tcb_to("view", &packed, dir.join("packed.html"), &[]);
    assert_success(&o);
    stderr_has(
        &o,
        "38 joints, 120 frames at 120.0005 fps (the clip's key times), 32 tracks in 31 plots",
    );

    // glTF: a skin's joints.
    let o = tcb_to(
        "view",
        file("data/simple_skin.gltf"),
        dir.join("skin.html"),
        &[],
    );
    assert_success(&o);
    stderr_has(&o, "joints");
}

#[test]
fn view_refuses_bad_input_in_one_line_and_writes_nothing() {
    let dir = scratch("view-errors");
    let out = dir.join("page.html");
    std::fs::write(&out, "kept").unwrap();
    let page = out.to_str().unwrap();
    let bvh = file("data/cmu-01_01.bvh");
    let missing = dir.join("missing.bvh");
    let cases: [(&[&str], &str); 7] = [
        (
            &["view", &bvh, "-o", "page.txt"],
            "page.txt: the output must end in .html",
        ),
        (
            &["view", missing.to_str().unwrap(), "-o", page],
            "missing.bvh",
        ),
        (
            &["view", &bvh, "-o", page, "--fps", "0"],
            "--fps must be a positive number, got 0",
        ),
        (
            &["view", &bvh, "-o", page, "--fps", "1e9"],
            "asks for more than 200000 frames",
        ),
        (
            &["view", &bvh, "-o", page, "--joint", "Hip"],
            "--joint Hip: no joint or group of tracks of that name (the clip's: Hips, LHipJoint,",
        ),
        (
            &["view", &bvh, "-o", "/no/such/folder/p.html"],
            "/no/such/folder: no such directory",
        ),
        (
            &["view", &bvh, "-o", page, "--animation", "0"],
            "--animation is for glTF files",
        ),
    ];
    for (args, message) in cases {
        let o = tcb(args);
        assert!(!o.status.success(), "{args:?}");
        let err = stderr(&o);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(
            err.starts_with("tcb: error: ") && err.contains(message),
            "{args:?}: {err}"
        );
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "kept", "{args:?}");
    }
    assert!(!Path::new("page.txt").exists());
}

/// What tools/view/check.mjs reports (the parts the tests judge).
#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Report {
    requests: Vec<String>,
    errors: Vec<String>,
    has_skeleton: bool,
    stage_visible: bool,
    joints: Vec<String>,
    groups: Vec<String>,
    shots: Vec<Shot>,
    playback: Playback,
    pick: Pick,
    orbit: Option<Orbit>,
    page_shot: PathBuf,
}

/// Where the joint the drag moved most was drawn before and after it.
#[derive(Deserialize)]
struct Orbit {
    /// The joint the drag moved most.
    joint: String,
    before: Point,
    after: Point,
}

#[derive(Deserialize)]
struct Shot {
    asked: f64,
    png: PathBuf,
    state: State,
    positions: HashMap<String, [f64; 3]>,
    root: Option<Point>,
    figure: Option<Pixels>,
}

#[derive(Deserialize)]
struct State {
    time: f64,
    playing: bool,
    speed: f64,
    picked: Option<String>,
    plot: Option<String>,
    cursor: Option<f64>,
}

#[derive(Deserialize)]
struct Point {
    x: f64,
    y: f64,
}

/// The figure's pixels in a screenshot.
#[derive(Deserialize, Debug)]
#[serde(rename_all = "camelCase")]
struct Pixels {
    pixels: u64,
    cx: Option<f64>,
    min_x: Option<f64>,
    max_y: Option<f64>,
}

#[derive(Deserialize)]
struct Playback {
    before: f64,
    playing: State,
    paused: State,
    button: String,
}

#[derive(Deserialize)]
#[serde(rename_all = "camelCase")]
struct Pick {
    clicked: Option<String>,
    after_click: Option<State>,
    chosen: String,
    after_choice: Choice,
}

#[derive(Deserialize)]
struct Choice {
    state: State,
    img: [u32; 2],
}

/// Why the browser tests cannot run here, if they cannot.
fn no_browser() -> Option<String> {
    let node = Command::new("node").arg("--version").output();
    if !node.is_ok_and(|o| o.status.success()) {
        return Some("node not found".into());
    }
    if !root()
        .join("tools/view/node_modules/playwright-core")
        .is_dir()
    {
        return Some("tools/view/node_modules missing (npm ci --prefix tools/view)".into());
    }
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    if !Path::new(&chromium).exists() {
        return Some(format!(
            "no Chromium at {chromium} (apt-get install chromium, or set CHROMIUM)"
        ));
    }
    None
}

/// Whether this is a CI run, where the browser tests must run.
fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0")
}

/// `tcb view CLIP`, opened by check.mjs at `times`; `None` when there is no
/// browser here and this is not CI.
fn check_in_browser(name: &str, clip: &str, times: &[&str]) -> Option<Report> {
    if let Some(why) = no_browser() {
        assert!(
            !in_ci(),
            "{why}: CI must run the browser tests (.ci/run installs what they need)"
        );
        eprintln!("skipped: {why}");
        return None;
    }
    let page = scratch("view-browser").join(format!("{name}.html"));
    let o = tcb_to("view", clip, &page, &[]);
    assert_success(&o);
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("view-shots")
        .join(name);
    let o = Command::new("node")
        .arg(root().join("tools/view/check.mjs"))
        .arg(&page)
        .arg(&shots)
        .args(times)
        .output()
        .expect("run node");
    assert!(o.status.success(), "check.mjs failed: {}", stderr(&o));
    eprint!("{}", stderr(&o));
    Some(serde_json::from_slice(&o.stdout).expect("check.mjs's report"))
}

#[test]
fn view_plays_the_cmu_jump_in_chromium_where_the_runtime_puts_it() {
    let Some(r) = check_in_browser("cmu", &file("data/cmu-01_01.bvh"), &["1", "2", "3"]) else {
        return;
    };
    assert!(r.requests.is_empty(), "the page fetched {:?}", r.requests);
    assert!(r.errors.is_empty(), "{:?}", r.errors);
    assert!(r.has_skeleton && r.stage_visible);
    assert_eq!(r.joints.len(), 38);
    assert_eq!(r.groups.len(), 31);
    joints_are_drawn_where_the_binding_puts_them(&r, "data/cmu-01_01.bvh");
    the_figure_follows_the_root_through_the_jump(&r);
    playback_orbit_and_picking_respond(&r);
    eprintln!(
        "screenshots: {} and {}",
        r.shots
            .iter()
            .map(|s| s.png.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        r.page_shot.display()
    );
}

/// Each shot's joint positions, as drawn, against `SkeletonBinding`'s at
/// the same time for the clip `clip` (under the repository).
fn joints_are_drawn_where_the_binding_puts_them(r: &Report, clip: &str) {
    let loaded = tcb_io::load(file(clip)).unwrap();
    let clip = Arc::new(tcb_runtime::Clip::compile(&loaded.clip));
    let binding = tcb_runtime::SkeletonBinding::new(loaded.skeleton.unwrap(), &clip);
    let mut instance = tcb_runtime::Instance::new(clip);
    let n = binding.skeleton().joints().len();
    let mut local = vec![tcb_core::skeleton::Transform::IDENTITY; n];
    let mut model = vec![glam::Affine3A::IDENTITY; n];
    let mut worst = 0.0f64;
    for s in &r.shots {
        assert!(
            (s.state.time - s.asked).abs() < 0.5 / 120.0,
            "{} at {}",
            s.asked,
            s.state.time
        );
        binding
            .model_transforms(instance.sample(s.state.time), &mut local, &mut model)
            .unwrap();
        assert_eq!(s.positions.len(), n);
        for (j, m) in binding.skeleton().joints().iter().zip(&model) {
            let drawn = s.positions[&j.name];
            for (d, m) in drawn.iter().zip(m.translation.to_array()) {
                worst = worst.max((d - f64::from(m)).abs());
            }
        }
    }
    eprintln!("largest difference of a drawn joint from SkeletonBinding: {worst:e}");
    assert!(worst <= 1e-5, "{worst:e}");
}

/// The screenshots at 1, 2 and 3 s of the CMU jump: the figure (its orange
/// bones) is where the root is drawn, and moves as the root does. Hips go
/// forward along +z from 1 s to 3 s, up in the jump at 2 s.
fn the_figure_follows_the_root_through_the_jump(r: &Report) {
    let hips = |s: &Shot| s.positions["Hips"];
    let [a, mid, b] = [&r.shots[0], &r.shots[1], &r.shots[2]];
    assert!(hips(b)[2] - hips(a)[2] > 10.0 && hips(mid)[1] - hips(a)[1] > 3.0);
    for s in &r.shots {
        let f = s.figure.as_ref().unwrap();
        let root = s.root.as_ref().unwrap();
        assert!(f.pixels > 1000, "{}: {f:?}", s.png.display());
        assert!(
            (f.cx.unwrap() - root.x).abs() < 40.0,
            "{}: figure at x {:?}, root drawn at {}",
            s.png.display(),
            f.cx,
            root.x
        );
        assert!(root.y.is_finite());
    }
    let (fa, fm, fb) = (
        a.figure.as_ref().unwrap(),
        mid.figure.as_ref().unwrap(),
        b.figure.as_ref().unwrap(),
    );
    let moved = fb.cx.unwrap() - fa.cx.unwrap();
    let expected = b.root.as_ref().unwrap().x - a.root.as_ref().unwrap().x;
    eprintln!(
        "figure moved {moved:.1} px across the view from 1 s to 3 s (root drawn {expected:.1} px); lowest pixel at 1, 2, 3 s: {:?}, {:?}, {:?}",
        fa.max_y, fm.max_y, fb.max_y
    );
    assert!(expected.abs() > 80.0, "{expected}");
    assert!(moved * expected > 0.0 && (moved - expected).abs() < 0.25 * expected.abs() + 10.0);
    // In the air at 2 s: the feet above where they stand at 1 s and 3 s.
    assert!(fm.max_y.unwrap() + 10.0 < fa.max_y.unwrap().min(fb.max_y.unwrap()));
}

/// Playback at the speed chosen, a drag that orbits the camera, and
/// picking a joint by a click and from the list.
fn playback_orbit_and_picking_respond(r: &Report) {
    let p = &r.playback;
    assert!(p.playing.playing && !p.paused.playing && p.button == "Play");
    assert!(p.playing.time != p.before && p.playing.speed == 2.0);
    let o = r.orbit.as_ref().unwrap();
    let turned = (o.after.x - o.before.x).hypot(o.after.y - o.before.y);
    eprintln!("a drag of 200 px moved {} {turned:.1} px", o.joint);
    assert!(turned > 20.0, "{turned}");
    let clicked = r.pick.clicked.as_deref().unwrap();
    let after = r.pick.after_click.as_ref().unwrap();
    assert_eq!(after.picked.as_deref(), Some(clicked));
    assert_eq!(after.plot.as_deref(), Some(clicked));
    let c = &r.pick.after_choice;
    assert_eq!(c.state.plot.as_deref(), Some(r.pick.chosen.as_str()));
    assert_eq!(c.img[0], 900);
    assert!(c.state.cursor.is_some());
}

#[test]
fn view_shows_a_clip_without_skeleton_as_its_curves_alone() {
    let Some(r) = check_in_browser(
        "bounce",
        &file("examples/clips/bounce.json"),
        &["0.5", "1.5"],
    ) else {
        return;
    };
    assert!(r.requests.is_empty(), "the page fetched {:?}", r.requests);
    assert!(r.errors.is_empty(), "{:?}", r.errors);
    assert!(!r.has_skeleton && !r.stage_visible);
    assert!(r.joints.is_empty());
    assert_eq!(r.groups, ["ball"]);
    let c = &r.pick.after_choice;
    assert_eq!(c.state.plot.as_deref(), Some("ball"));
    assert!(c.img[0] == 900 && c.img[1] > 560);
    // The cursor on the curves follows the timeline.
    let x: Vec<f64> = r.shots.iter().map(|s| s.state.cursor.unwrap()).collect();
    assert!(x[1] > x[0] + 100.0, "{x:?}");
    assert!(
        r.shots
            .iter()
            .all(|s| s.positions.is_empty() && s.figure.is_none())
    );
    eprintln!(
        "screenshots: {}, {}",
        r.shots[0].png.display(),
        r.page_shot.display()
    );
}

#[test]
fn view_shows_a_leaf_joints_rotation_as_its_tip() {
    // simple_skin.gltf rotates node2, a joint with no child: no joint moves.
    let Some(r) = check_in_browser("skin", &file("data/simple_skin.gltf"), &["0", "2"]) else {
        return;
    };
    assert!(
        r.requests.is_empty() && r.errors.is_empty(),
        "{:?} {:?}",
        r.requests,
        r.errors
    );
    assert_eq!(r.joints, ["node0", "node1", "node2"]);
    // The root has no track: the first group's curves show.
    assert_eq!(r.shots[0].state.plot.as_deref(), Some("node2"));
    let (a, b) = (&r.shots[0], &r.shots[1]);
    for j in &r.joints {
        assert_eq!(a.positions[j], b.positions[j], "{j}");
    }
    let (fa, fb) = (a.figure.as_ref().unwrap(), b.figure.as_ref().unwrap());
    eprintln!(
        "the tip's pixels: left edge {:?} at 0 s, {:?} at 2 s",
        fa.min_x, fb.min_x
    );
    assert!(
        fa.min_x.unwrap() - fb.min_x.unwrap() > 10.0,
        "{fa:?} {fb:?}"
    );
}
