//! Any clip can be plotted: one panel per kind, tracks a mode cannot draw
//! skipped with a note, legends beside the curves, and a rig's path on its
//! ground plane.

use std::path::Path;
use tcb_core::skeleton::{Joint, Skeleton, Transform};
use tcb_plot::{Mode, Plot, render_with_notes};

fn load(clip: &str) -> tcb_core::SourceClip {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    tcb_io::load(root.join(clip)).unwrap().clip
}

fn plot(mode: Mode) -> Plot {
    Plot {
        mode,
        ..Plot::new("t")
    }
}

/// The numbers of an SVG attribute list `name="a,b c,d ..."`.
fn numbers(attr: &str) -> Vec<f64> {
    attr.split([' ', ','])
        .filter_map(|n| n.parse().ok())
        .collect()
}

/// The value of attribute `name` in the tag `tag`.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&tag[start..start + tag[start..].find('"')?])
}

/// Every tag of `svg` called `name`, as its text up to `>`.
fn tags<'a>(svg: &'a str, name: &str) -> Vec<&'a str> {
    svg.match_indices(&format!("<{name} "))
        .map(|(i, _)| &svg[i..i + svg[i..].find('>').unwrap()])
        .collect()
}

/// The right-most x of any curve (a polyline of more than two points:
/// axes, ticks and legend glyphs have two) or key and inbetween dot (in a
/// track's colour: the legend's dots are black).
fn rightmost_mark(svg: &str) -> f64 {
    let curves = tags(svg, "polyline")
        .into_iter()
        .filter_map(|t| attr(t, "points"))
        .map(numbers)
        .filter(|p| p.len() > 4)
        .flat_map(|p| p.chunks(2).map(|xy| xy[0]).collect::<Vec<_>>());
    let dots = tags(svg, "circle")
        .into_iter()
        .filter(|t| !t.contains("\"#000000\""))
        .filter_map(|t| attr(t, "cx")?.parse::<f64>().ok());
    curves.chain(dots).fold(f64::NEG_INFINITY, f64::max)
}

/// The x at which the text `label` is drawn.
fn text_x(svg: &str, label: &str) -> f64 {
    let tag = svg
        .match_indices("<text ")
        .map(|(i, _)| &svg[i..i + svg[i..].find("</text>").unwrap()])
        .filter(|t| t[t.find('>').unwrap() + 1..].trim() == label)
        // The last: a panel's caption may say the same as its legend, which
        // is drawn after it.
        .last()
        .unwrap_or_else(|| panic!("no text {label}"));
    attr(tag, "x").unwrap().parse().unwrap()
}

#[test]
fn a_clip_of_every_kind_gets_a_panel_each() {
    let bounce = load("examples/clips/bounce.json");
    for mode in [Mode::Value, Mode::Velocity, Mode::Speed] {
        let r = render_with_notes(&bounce, &plot(mode)).unwrap();
        for caption in ["vector tracks", "rotation tracks", "scalar tracks"] {
            assert_eq!(r.svg.matches(caption).count(), 1, "{mode:?} {caption}");
        }
        assert!(r.notes.is_empty(), "{:?}", r.notes);
    }
    // Values of rotations are angle and axis: two charts in their panel.
    let r = render_with_notes(&bounce, &plot(Mode::Value)).unwrap();
    assert!(r.svg.contains("rotation angle (degrees)"));
    assert!(r.svg.contains("rotation axis (unit vector)"));
    // One kind: one panel, captioned by the title and the track names.
    let careen = load("examples/clips/careen.json");
    let r = render_with_notes(&careen, &plot(Mode::Value)).unwrap();
    assert!(!r.svg.contains("vector tracks"));
    assert!(
        r.svg
            .contains("t: ball.path, ball.path_overshoot, ball.path_stop")
    );
}

#[test]
fn path_and_components_skip_what_they_cannot_draw_and_say_so() {
    let bounce = load("examples/clips/bounce.json");
    let r = render_with_notes(&bounce, &plot(Mode::Path { components: [0, 1] })).unwrap();
    assert_eq!(
        r.notes,
        [
            "--path draws two components (x, y) of a vector track; skipping 'ball.squash' (scalar), 'ball.rotation' (quat)"
        ]
    );
    assert!(r.svg.contains("ball.position") && !r.svg.contains("ball.squash"));
    let r = render_with_notes(&bounce, &plot(Mode::Components)).unwrap();
    assert_eq!(
        r.notes,
        [
            "--components draws rotation tracks; skipping 'ball.position' (vec3), 'ball.squash' (scalar)"
        ]
    );
    assert!(r.svg.contains("quaternion components"));
    // Nothing left to draw is an error, in one line.
    let spin = load("examples/clips/spin.json");
    let e = render_with_notes(&spin, &plot(Mode::Path { components: [0, 1] }))
        .unwrap_err()
        .to_string();
    assert!(e.contains("'top.squad' is quat (4 components)"), "{e}");
    assert!(!e.contains('\n'));
    // Many skipped tracks are counted by kind.
    let cmu = load("data/cmu-01_01.bvh");
    let r = render_with_notes(&cmu, &plot(Mode::Path { components: [0, 2] })).unwrap();
    assert_eq!(
        r.notes,
        ["--path draws two components (x, z) of a vector track; skipping 31 quat tracks"]
    );
}

#[test]
fn a_big_clip_shows_the_first_tracks_of_each_kind_and_says_so() {
    let cmu = load("data/cmu-01_01.bvh");
    let r = render_with_notes(&cmu, &plot(Mode::Value)).unwrap();
    assert_eq!(
        r.notes,
        ["plotting the first 4 of 31 rotation tracks (choose others with --track)"]
    );
    assert!(r.svg.contains("Hips.translation.x") && r.svg.contains("angle of LeftLeg.rotation"));
    assert!(!r.svg.contains("angle of RightLeg.rotation"));
}

#[test]
fn paths_are_small_multiples_one_panel_a_track() {
    // Three paths of one ball drawn on one pair of axes hid each other.
    let careen = load("examples/clips/careen.json");
    let svg = render_with_notes(&careen, &plot(Mode::Path { components: [0, 1] }))
        .unwrap()
        .svg;
    for name in ["ball.path", "ball.path_overshoot", "ball.path_stop"] {
        // Its panel's caption and its legend.
        let texts = svg
            .match_indices("<text ")
            .map(|(i, _)| &svg[i..i + svg[i..].find("</text>").unwrap()])
            .filter(|t| t[t.find('>').unwrap() + 1..].trim() == name)
            .count();
        assert_eq!(texts, 2, "{name}");
    }
}

#[test]
fn legends_sit_beside_the_curves() {
    let careen = load("examples/clips/careen.json");
    let bounce = load("examples/clips/bounce.json");
    for (clip, mode, label) in [
        (
            &careen,
            Mode::Path { components: [0, 1] },
            "ball.path_overshoot",
        ),
        (&careen, Mode::Speed, "speed of ball.path"),
        (&bounce, Mode::Value, "ball.position.x"),
        (&bounce, Mode::Value, "axis.z of ball.rotation"),
    ] {
        let svg = render_with_notes(clip, &plot(mode)).unwrap().svg;
        // The legend's glyphs take 30 pixels before its labels.
        let legend = text_x(&svg, label) - 30.0;
        let right = rightmost_mark(&svg);
        assert!(
            right < legend,
            "{mode:?}: a curve at x {right}, the legend from {legend}"
        );
    }
}

/// A two-joint rig whose child stands 1 above its root along `up`.
fn rig(up: glam::Vec3) -> Skeleton {
    let at = |t: glam::Vec3| Transform {
        translation: t,
        ..Transform::IDENTITY
    };
    Skeleton::new(vec![
        Joint {
            name: "root".into(),
            parent: None,
            rest: at(glam::Vec3::ZERO),
        },
        Joint {
            name: "head".into(),
            parent: Some(0),
            rest: at(up + 0.3 * glam::Vec3::X),
        },
    ])
    .unwrap()
}

#[test]
fn a_rigs_path_is_drawn_on_its_ground_plane() {
    assert_eq!(tcb_plot::ground_plane(&rig(glam::Vec3::Y)), [0, 2]);
    assert_eq!(tcb_plot::ground_plane(&rig(glam::Vec3::Z)), [0, 1]);
    assert_eq!(tcb_plot::ground_plane(&Skeleton::default()), [0, 2]);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for rig in ["data/cmu-01_01.bvh", "data/simple_skin.gltf"] {
        let skeleton = tcb_io::load(root.join(rig)).unwrap().skeleton.unwrap();
        assert_eq!(tcb_plot::ground_plane(&skeleton), [0, 2], "{rig}");
    }
}
