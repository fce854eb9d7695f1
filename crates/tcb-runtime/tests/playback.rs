//! Playback at the instance: loop, clamp, ping-pong and speed, whatever
//! the clip's pre/post, against a plain instance sampled at the clip time
//! worked out here (values equal to the bit; velocities scaled).

use std::sync::Arc;
use tcb_runtime::{Clip, Instance, Playback};

const BOUNCE: &str = include_str!("../../../examples/clips/bounce.json");

/// The clip time of `t` under `mode` at `speed` over keys `[a, b]`, and
/// the velocity factor.
fn expected(mode: Playback, speed: f64, t: f64, (a, b): (f64, f64)) -> (f64, f32) {
    let t = t * speed;
    let d = b - a;
    match mode {
        Playback::Clip => (t, speed as f32),
        Playback::Clamp if t < a => (a, 0.0),
        Playback::Clamp if t > b => (b, 0.0),
        Playback::Clamp => (t, speed as f32),
        Playback::Loop => (a + (t - a).rem_euclid(d), speed as f32),
        Playback::PingPong => {
            let u = (t - a).rem_euclid(2.0 * d);
            if u <= d {
                (a + u, speed as f32)
            } else {
                (b - (u - d), -speed as f32)
            }
        }
    }
}

#[test]
fn every_mode_and_speed_matches_the_clip_at_the_mapped_time() {
    let source = tcb_io::ClipDoc::parse(BOUNCE).unwrap().build().unwrap();
    let clip = Arc::new(Clip::compile(&source));
    let range = clip.time_range().unwrap();
    let n = source.channel_count();
    let times: Vec<f64> = (0..400)
        .map(|i| -3.0 + 0.037 * f64::from(i))
        .chain([1e6, 1e6 + 0.25, -1e6])
        .collect();
    for mode in [
        Playback::Clip,
        Playback::Loop,
        Playback::Clamp,
        Playback::PingPong,
    ] {
        for speed in [1.0, 2.0, -0.5] {
            let mut played = Instance::new(clip.clone()).with_velocities();
            played.set_playback(mode, speed).unwrap();
            assert_eq!(played.playback(), (mode, speed));
            let mut plain = Instance::new(clip.clone()).with_velocities();
            let (mut gv, mut gd, mut wv, mut wd) =
                (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            for &t in &times {
                let (ct, rate) = expected(mode, speed, t, range);
                played.sample(t).write_row(&mut gv, Some(&mut gd));
                plain.sample(ct).write_row(&mut wv, Some(&mut wd));
                assert_eq!(gv, wv, "{mode:?} x{speed} t={t}: values at clip time {ct}");
                for (g, w) in gd.iter().zip(&wd) {
                    assert_eq!(*g, w * rate, "{mode:?} x{speed} t={t}: velocity");
                }
            }
        }
    }
}

#[test]
fn looping_far_from_zero_is_as_exact_as_near_it() {
    let source = tcb_io::ClipDoc::parse(BOUNCE).unwrap().build().unwrap();
    let clip = Arc::new(Clip::compile(&source));
    let (a, b) = clip.time_range().unwrap();
    let mut inst = Instance::new(clip);
    inst.set_playback(Playback::Loop, 1.0).unwrap();
    let n = source.channel_count();
    let (mut near, mut far) = (vec![0.0; n], vec![0.0; n]);
    let cycles = 1e6_f64.div_euclid(b - a);
    let offset = 0.3;
    inst.sample(a + offset).write_row(&mut near, None);
    inst.sample(a + cycles * (b - a) + offset)
        .write_row(&mut far, None);
    for (x, y) in near.iter().zip(&far) {
        assert!((x - y).abs() < 1e-5, "{x} vs {y}");
    }
}

#[test]
fn a_speed_that_is_not_finite_is_refused() {
    let source = tcb_io::ClipDoc::parse(BOUNCE).unwrap().build().unwrap();
    let mut inst = Instance::new(Arc::new(Clip::compile(&source)));
    for bad in [f64::NAN, f64::INFINITY] {
        let e = inst.set_playback(Playback::Loop, bad).unwrap_err();
        assert!(e.to_string().contains("not a finite number"), "{e}");
    }
    assert_eq!(inst.playback(), (Playback::Clip, 1.0));
}
