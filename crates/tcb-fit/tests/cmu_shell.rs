//! `tcb reduce` on the bundled CMU clip, checked by a metric written here
//! from `docs/reduce.md` alone: its own BVH hierarchy reader, its own check
//! times, and its own forward kinematics in f64. Only the playing of the
//! clips (the runtime, as `tcb sample` plays them) is shared with the fitter.

use glam::{DAffine3, DQuat, DVec3};
use std::sync::Arc;
use tcb_fit::{Knots, ReduceOptions, Tangents};

const BVH: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");

/// The hierarchy as this test reads it: names, parents, offsets, with End
/// Sites as leaf joints.
struct Rig {
    names: Vec<String>,
    parents: Vec<Option<usize>>,
    offsets: Vec<DVec3>,
    frames: usize,
    frame_time: f64,
}

fn read_rig(text: &str) -> Rig {
    let mut rig = Rig {
        names: Vec::new(),
        parents: Vec::new(),
        offsets: Vec::new(),
        frames: 0,
        frame_time: 0.0,
    };
    let mut stack: Vec<usize> = Vec::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["ROOT" | "JOINT", name] => {
                rig.names.push((*name).to_owned());
                rig.parents.push(stack.last().copied());
                rig.offsets.push(DVec3::ZERO);
            }
            ["End", "Site"] => {
                let parent = *stack.last().unwrap();
                rig.names.push(format!("{}_end", rig.names[parent]));
                rig.parents.push(Some(parent));
                rig.offsets.push(DVec3::ZERO);
            }
            ["{"] => stack.push(rig.names.len() - 1),
            ["}"] => {
                stack.pop();
            }
            ["OFFSET", x, y, z] => {
                let at = rig.names.len() - 1;
                rig.offsets[at] =
                    DVec3::new(x.parse().unwrap(), y.parse().unwrap(), z.parse().unwrap());
            }
            ["Frames:", n] => rig.frames = n.parse().unwrap(),
            ["Frame", "Time:", t] => rig.frame_time = t.parse().unwrap(),
            _ => {}
        }
    }
    rig
}

/// Model-space transforms from per-joint translations and rotations.
fn model(rig: &Rig, local: &[(DVec3, DQuat)]) -> Vec<DAffine3> {
    let mut out: Vec<DAffine3> = Vec::with_capacity(local.len());
    for (j, (t, r)) in local.iter().enumerate() {
        let m = DAffine3::from_rotation_translation(*r, *t);
        out.push(match rig.parents[j] {
            Some(p) => out[p] * m,
            None => m,
        });
    }
    out
}

/// Each joint's local transform at `row` of a clip sampled into columns.
fn locals(rig: &Rig, columns: &[String], row: &[f32]) -> Vec<(DVec3, DQuat)> {
    let find = |name: String| columns.iter().position(|c| *c == name);
    (0..rig.names.len())
        .map(|j| {
            let n = &rig.names[j];
            let t = find(format!("{n}.translation.x")).map_or(rig.offsets[j], |i| {
                DVec3::new(row[i].into(), row[i + 1].into(), row[i + 2].into())
            });
            let r = find(format!("{n}.rotation.x")).map_or(DQuat::IDENTITY, |i| {
                DQuat::from_xyzw(
                    row[i].into(),
                    row[i + 1].into(),
                    row[i + 2].into(),
                    row[i + 3].into(),
                )
                .normalize()
            });
            (t, r)
        })
        .collect()
}

fn play(clip: &tcb_core::SourceClip, times: &[f64]) -> Vec<Vec<f32>> {
    let mut instance = tcb_runtime::Instance::new(Arc::new(tcb_runtime::Clip::compile(clip)));
    times
        .iter()
        .map(|&t| {
            let mut row = vec![0.0; clip.channel_count()];
            instance.sample(t).write_row(&mut row, None);
            row
        })
        .collect()
}

/// The shell error by the contract, computed here.
fn shell_error(
    rig: &Rig,
    input: &tcb_core::SourceClip,
    output: &tcb_core::SourceClip,
    radius: f64,
) -> f64 {
    // Check times: every frame and 3 inbetweens between frames.
    let mut times = Vec::new();
    for f in 0..rig.frames {
        let t = f as f64 * rig.frame_time;
        if f > 0 {
            let prev = (f - 1) as f64 * rig.frame_time;
            times.extend((1..=3).map(|j| prev + (t - prev) * (j as f64 / 4.0)));
        }
        times.push(t);
    }
    let (ca, cb) = (input.column_names(), output.column_names());
    assert_eq!(ca, cb);
    let (ra, rb) = (play(input, &times), play(output, &times));
    let points = [
        DVec3::ZERO,
        DVec3::X * radius,
        DVec3::Y * radius,
        DVec3::Z * radius,
    ];
    let mut worst = 0.0f64;
    for (a, b) in ra.iter().zip(&rb) {
        let (ma, mb) = (
            model(rig, &locals(rig, &ca, a)),
            model(rig, &locals(rig, &cb, b)),
        );
        for (x, y) in ma.iter().zip(&mb) {
            for v in points {
                worst = worst.max((x.transform_point3(v) - y.transform_point3(v)).length());
            }
        }
    }
    worst
}

fn rest_height(rig: &Rig) -> f64 {
    let rest: Vec<(DVec3, DQuat)> = rig.offsets.iter().map(|o| (*o, DQuat::IDENTITY)).collect();
    let m = model(rig, &rest);
    m.iter()
        .map(|a| (a.translation - m[0].translation).length())
        .fold(0.0, f64::max)
}

#[test]
fn reduced_cmu_is_within_the_shell_tolerance_at_three_tolerances() {
    let text = std::fs::read_to_string(BVH).unwrap();
    let rig = read_rig(&text);
    let loaded = tcb_io::load(BVH).unwrap();
    let skeleton = loaded.skeleton.clone().unwrap();
    assert_eq!(skeleton.joints().len(), rig.names.len());
    let h = rest_height(&rig);
    let (default_e, radius) = (6e-5 * h, 0.018 * h);
    for scale in [1.0, 10.0, 0.1] {
        let options = ReduceOptions::default()
            .tolerance((scale != 1.0).then_some(scale * default_e))
            .knots(Knots::Track)
            .tangents(Tangents::Derived);
        let input = tcb_fit::reduce::Input {
            doc: &loaded.doc,
            clip: &loaded.clip,
            skeleton: Some(&skeleton),
        };
        let reduced = tcb_fit::reduce(input, &options, &|_, _| {}).unwrap();
        let s = &reduced.settings;
        assert!((s.tolerance - scale * default_e).abs() < 1e-6 * default_e);
        assert!((s.shell - radius).abs() < 1e-6 * radius);
        // What a user gets: the file as written, parsed and built again.
        let clip = tcb_io::ClipDoc::parse(&reduced.doc.to_json())
            .unwrap()
            .build()
            .unwrap();
        let e = shell_error(&rig, &loaded.clip, &clip, radius);
        assert!(
            e <= s.tolerance,
            "scale {scale}: error {e} over {}",
            s.tolerance
        );
        // The fitter's own measure agrees with this one.
        assert!(
            (e - reduced.worst.error).abs() <= 1e-3 * s.tolerance,
            "{e} vs {}",
            reduced.worst.error
        );
        assert!(
            reduced.after.values < reduced.before.values,
            "scale {scale}"
        );
        sign_continuous(&reduced.doc);
    }
}

/// No rotation key's dot product with the previous key is negative.
fn sign_continuous(doc: &tcb_io::ClipDoc) {
    for t in doc
        .tracks
        .iter()
        .filter(|t| t.kind == tcb_core::TrackKind::Quat)
    {
        for w in t.values.windows(2) {
            let dot: f32 = (0..4).map(|c| w[0][c] * w[1][c]).sum();
            assert!(dot >= 0.0, "{}: {dot}", t.name);
        }
    }
}
