//! Issue 29, class 5: a looping or ping-pong instance plays inside its
//! keys whatever the time, so the clip's own `pre` and `post` never apply.
//! Here both are `reset` (the curve stays between 4 and 10, reset gives
//! 0), and times around every turn of the loop, up to 20 ulps either side,
//! must give a value of the curve.

use std::sync::Arc;
use tcb_runtime::{Clip, Instance, Playback};

fn ulps(x: f64, n: i64) -> f64 {
    f64::from_bits((x.to_bits() as i64 + n) as u64)
}

#[test]
fn loop_and_ping_pong_stay_inside_the_keys_at_their_turns() {
    let mut bad = Vec::new();
    for (t0, t1) in [
        (0.1, 0.7),
        (-7.3, 1.0 / 3.0),
        (1e3 + 0.1, 1e3 + 0.4),
        (1e6 / 3.0, 1e6 / 3.0 + 0.01),
        (0.0, 1e-3),
        (3.15e7, 3.15e7 + 0.125),
        (0.3, 0.9),
        (1.1, 2.3),
    ] {
        check(t0, t1, &mut bad);
    }
    assert!(
        bad.is_empty(),
        "{} outside the keys: {:?}",
        bad.len(),
        &bad[..bad.len().min(5)]
    );
}

fn check(t0: f64, t1: f64, bad: &mut Vec<String>) {
    let mid = t0 + (t1 - t0) / 2.0;
    let text = format!(
        r#"{{"format": "tcb-clip/1", "tracks": [
      {{"name": "x", "kind": "scalar", "times": [{t0:?}, {mid:?}, {t1:?}], "values": [5, 9, 6],
       "pre": "reset", "post": "reset"}}]}}"#
    );
    let clip = Arc::new(Clip::compile(
        &tcb_io::ClipDoc::parse(&text).unwrap().build().unwrap(),
    ));
    let x = clip.track("x").unwrap();
    for mode in [Playback::Loop, Playback::PingPong] {
        for speed in [1.0, -1.0, 3.0, 0.1] {
            let mut inst = Instance::new(clip.clone());
            inst.set_playback(mode, speed).unwrap();
            for k in -40i32..40 {
                // Turns of the loop (every d) and of the ping-pong (every 2d).
                let turn = t0 + f64::from(k) * (t1 - t0) / 2.0;
                for n in -20..=20 {
                    let t = ulps(turn, n) / speed;
                    let v = inst.sample(t).scalar(x).unwrap();
                    if !(v > 4.0 && v < 10.0) {
                        bad.push(format!("{t0}..{t1} {mode:?} x{speed} at {t:e}: {v}"));
                    }
                }
            }
        }
    }
}
