//! Playback at the instance: loop, clamp, ping-pong and speed, whatever
//! the clip's pre/post, against a plain instance sampled at a clip time
//! worked out by hand for each case (values equal to the bit; velocities
//! scaled by the rate worked out with it).

use std::sync::Arc;
use tcb_runtime::{Clip, Instance, Playback};

const BOUNCE: &str = include_str!("../../../examples/clips/bounce.json");

/// `bounce.json` moved half a second later: keys from t0 = 0.5 to
/// t1 = 2.5 (d = 2), so that a mapping that forgot t0 shows. The position
/// oscillates after its last key, so `Playback::Clip` differs from the
/// other modes past the end.
const LATE_BOUNCE: &str = r#"{"format": "tcb-clip/1", "name": "late-bounce", "tracks": [
  {"name": "ball.position", "kind": "vec3", "times": [0.5, 1.0, 1.75, 2.5],
   "values": [[0, 0, 0], [1, 2, 0], [2, 0, 0], [3, 1, 0]],
   "keys": [{}, {"tcb": [0.0, -1.0, 0.0]}, {"ease": [0.5, 0.0]}, {}], "post": "oscillate"},
  {"name": "ball.squash", "kind": "scalar", "times": [0.5, 1.75], "values": [1.0, 0.6]},
  {"name": "ball.rotation", "kind": "quat", "times": [0.5, 1.0, 1.75, 2.5],
   "values": [[0, 0, 0, 1], [0, 0, 0.3826834, 0.9238795], [0, 0, 0.7071068, 0.7071068], [0, 0, 1, 0]]}]}"#;

/// 2^100: a huge speed whose products below are exact. It is a multiple
/// of 4 and its ulp is 2^48, so 2^100 - 0.5 rounds to 2^100, and its
/// cycles leave remainder 0.
const HUGE: f64 = (1u128 << 100) as f64;

/// One case: `mode` at `speed`, asked for time `t`, plays the clip at
/// `clip_time` with velocities times `rate`.
struct Case {
    mode: Playback,
    speed: f64,
    t: f64,
    clip_time: f64,
    rate: f32,
}

const fn case(mode: Playback, speed: f64, t: f64, clip_time: f64, rate: f32) -> Case {
    Case {
        mode,
        speed,
        t,
        clip_time,
        rate,
    }
}

/// Over keys [0.5, 2.5]: s = speed * t; Loop plays 0.5 + (s - 0.5) mod 2,
/// PingPong takes u = (s - 0.5) mod 4 and plays 0.5 + u forwards while
/// u <= 2, else 0.5 + 4 - u backwards (rate -speed).
#[rustfmt::skip]
const CASES: &[Case] = &[
    // Clip: s itself, the clip's own pre/post outside the keys.
    case(Playback::Clip, 1.0, 3.0, 3.0, 1.0),        // past the end: post (oscillate)
    case(Playback::Clip, -0.5, 3.0, -1.5, -0.5),     // s = -1.5, before the first key
    case(Playback::Clip, 0.0, 7.0, 0.0, 0.0),        // s = 0 whatever t is
    // Loop.
    case(Playback::Loop, 1.0, 0.5, 0.5, 1.0),        // at t0
    case(Playback::Loop, 1.0, 2.25, 2.25, 1.0),      // inside
    case(Playback::Loop, 1.0, 2.5, 0.5, 1.0),        // at t1: 2 mod 2 = 0, back to t0
    case(Playback::Loop, 1.0, 2.75, 0.75, 1.0),      // just past t1: 2.25 mod 2 = 0.25
    case(Playback::Loop, 1.0, 0.25, 2.25, 1.0),      // just before t0: -0.25 mod 2 = 1.75
    case(Playback::Loop, 1.0, -3.5, 0.5, 1.0),       // -4 mod 2 = 0
    case(Playback::Loop, 1.0, 1e6 + 0.25, 2.25, 1.0), // 999999.75 mod 2 = 1.75
    case(Playback::Loop, -1.0, 1.0, 1.0, -1.0),      // s = -1: -1.5 mod 2 = 0.5
    case(Playback::Loop, 0.0, 5.0, 2.0, 0.0),        // s = 0: -0.5 mod 2 = 1.5
    case(Playback::Loop, HUGE, 1.0, 0.5, HUGE as f32), // s = 2^100: 2^100 mod 2 = 0
    case(Playback::Loop, 1.0, f64::INFINITY, 0.5, 0.0), // no cycle: held at t0
    case(Playback::Loop, 1.0, f64::NAN, 0.5, 0.0),   // likewise
    // Clamp.
    case(Playback::Clamp, 1.0, 0.25, 0.5, 0.0),      // before t0: held there, still
    case(Playback::Clamp, 1.0, 0.5, 0.5, 1.0),       // at t0: moving
    case(Playback::Clamp, 1.0, 2.5, 2.5, 1.0),       // at t1: moving
    case(Playback::Clamp, 1.0, 2.75, 2.5, 0.0),      // after t1: held there, still
    case(Playback::Clamp, -1.0, -1.0, 1.0, -1.0),    // s = 1, backwards
    case(Playback::Clamp, -1.0, 1.0, 0.5, 0.0),      // s = -1 < t0
    case(Playback::Clamp, 0.0, 9.0, 0.5, 0.0),       // s = 0 < t0
    case(Playback::Clamp, HUGE, 2.0 / HUGE, 2.0, HUGE as f32), // s = 2^100 * 2^-99 = 2
    case(Playback::Clamp, 1.0, f64::INFINITY, 2.5, 0.0),
    case(Playback::Clamp, 1.0, f64::NEG_INFINITY, 0.5, 0.0),
    // PingPong.
    case(Playback::PingPong, 1.0, 0.5, 0.5, 1.0),    // u = 0: at t0, forwards
    case(Playback::PingPong, 1.0, 1.5, 1.5, 1.0),    // u = 1
    case(Playback::PingPong, 1.0, 2.5, 2.5, 1.0),    // u = 2: at t1, still forwards
    case(Playback::PingPong, 1.0, 3.0, 2.0, -1.0),   // u = 2.5: 4.5 - 2.5, backwards
    case(Playback::PingPong, 1.0, 4.25, 0.75, -1.0), // u = 3.75: 4.5 - 3.75
    case(Playback::PingPong, 1.0, 4.5, 0.5, 1.0),    // u = 4 mod 4 = 0: forwards again
    case(Playback::PingPong, 1.0, 0.25, 0.75, -1.0), // u = -0.25 mod 4 = 3.75
    case(Playback::PingPong, -1.0, -1.5, 1.5, -1.0), // s = 1.5, u = 1: rate = speed
    case(Playback::PingPong, -1.0, -3.0, 2.0, 1.0),  // s = 3, u = 2.5: rate = -speed
    case(Playback::PingPong, 2.0, 1.5, 2.0, -2.0),   // s = 3, u = 2.5
    case(Playback::PingPong, 0.0, 3.0, 1.0, -0.0),   // s = 0, u = -0.5 mod 4 = 3.5
    case(Playback::PingPong, HUGE, 1.0, 0.5, HUGE as f32), // s = 2^100: u = 0
    case(Playback::PingPong, 1.0, f64::NEG_INFINITY, 0.5, 0.0), // no cycle: held at t0
];

#[test]
fn every_mode_and_speed_plays_the_clip_time_worked_out_by_hand() {
    let source = tcb_io::ClipDoc::parse(LATE_BOUNCE)
        .unwrap()
        .build()
        .unwrap();
    let clip = Arc::new(Clip::compile(&source));
    assert_eq!(clip.time_range(), Some((0.5, 2.5)));
    let n = source.channel_count();
    let (mut gv, mut gd, mut wv, mut wd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for c in CASES {
        let what = format!("{:?} x{} t={}", c.mode, c.speed, c.t);
        let mut played = Instance::new(clip.clone()).with_velocities();
        played.set_playback(c.mode, c.speed).unwrap();
        assert_eq!(played.playback(), (c.mode, c.speed));
        let mut plain = Instance::new(clip.clone()).with_velocities();
        played.sample(c.t).write_row(&mut gv, Some(&mut gd));
        plain.sample(c.clip_time).write_row(&mut wv, Some(&mut wd));
        assert_eq!(gv, wv, "{what}: values at clip time {}", c.clip_time);
        for (g, w) in gd.iter().zip(&wd) {
            assert_eq!(*g, w * c.rate, "{what}: velocity at rate {}", c.rate);
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
