//! Properties of the reference spline over random tracks.

use glam::{DQuat, DVec4, Quat, Vec2, Vec3};
use proptest::prelude::*;
use tcb_core::rotation::{quat_exp, quat_log, squad};
use tcb_core::tangent::ChordWeights;
use tcb_core::{
    Ends, Extrapolation, KeyParams, RotationMode, RotationTrack, TangentRule, Tcb, Track,
    TrackSettings, Vector,
};
use tcb_test_support::proptest_config;

const RULES: [TangentRule; 4] = [
    TangentRule::Uniform,
    TangentRule::Adjusted,
    TangentRule::Secant,
    TangentRule::Parabolic,
];

/// Strictly increasing times with gaps between 0.05 and 3.
fn times(n: usize) -> impl Strategy<Value = Vec<f64>> {
    (-5.0..5.0f64, prop::collection::vec(0.05..3.0f64, n - 1)).prop_map(|(start, gaps)| {
        let mut t = vec![start];
        for g in gaps {
            let next = t[t.len() - 1] + g;
            t.push(next);
        }
        t
    })
}

fn tcb() -> impl Strategy<Value = Tcb> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64).prop_map(|(t, c, b)| Tcb::new(t, c, b))
}

fn vec3() -> impl Strategy<Value = Vec3> {
    (-10.0..10.0f32, -10.0..10.0f32, -10.0..10.0f32).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A random track: times, values, per-key TCB.
fn track3(max: usize) -> impl Strategy<Value = (Vec<f64>, Vec<Vec3>, Vec<Tcb>)> {
    (2..max).prop_flat_map(|n| {
        (
            times(n),
            prop::collection::vec(vec3(), n),
            prop::collection::vec(tcb(), n),
        )
    })
}

fn keys<V>(tcbs: &[Tcb]) -> Vec<KeyParams<V>> {
    tcbs.iter().map(|&t| KeyParams::with_tcb(t)).collect()
}

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * a.abs().max_element().max(b.abs().max_element()).max(1.0)
}

fn quat_close(a: Quat, b: Quat, tol: f32) -> bool {
    (a - b).length().min((a + b).length()) <= tol
}

proptest! {
    #![proptest_config(proptest_config(200))]

    /// Keys clustered over 15 orders of magnitude, spans that overflow
    /// f64 when subtracted: the seek's guess (evenly spaced keys) lands
    /// far off, or nowhere, and the search still finds the segment.
    #[test]
    fn segment_search_with_uneven_keys_is_the_binary_search(
        n in 2..70usize,
        exps in prop::collection::vec(-9.0..6.0f64, 70),
        start in prop::sample::select(vec![0.0, -1e300, 1e290, -5.0]),
        scale in prop::sample::select(vec![1.0, 1e295]),
        hint in 0..80usize,
        probe in 0.0..1.0f64,
    ) {
        let mut times = vec![start];
        for e in &exps[..n - 1] {
            let next = times[times.len() - 1] + 10f64.powf(*e) * scale;
            prop_assume!(next.is_finite() && next > times[times.len() - 1]);
            times.push(next);
        }
        let (t0, tn) = (times[0], times[n - 1]);
        let mut probes: Vec<f64> = times.clone();
        probes.extend([t0 + probe * (tn - t0), t0 * (1.0 - probe) + tn * probe, -f64::MAX, f64::MAX]);
        for t in probes {
            let plain = times.partition_point(|&x| x <= t).saturating_sub(1).min(n - 2);
            prop_assert_eq!(tcb_core::track::segment_from(&times, t, hint), plain, "time {}", t);
        }
    }

    #[test]
    fn segment_search_from_any_hint_is_the_binary_search(
        n in 2..70usize,
        seed in prop::collection::vec(0.05..3.0f64, 70),
        hint in 0..80usize,
        time in -10.0..200.0f64,
    ) {
        let mut times = vec![0.0];
        for g in &seed[..n - 1] {
            let next = times[times.len() - 1] + g;
            times.push(next);
        }
        let plain = times.partition_point(|&t| t <= time).saturating_sub(1).min(n - 2);
        prop_assert_eq!(tcb_core::track::segment_from(&times, time, hint), plain);
        for &t in &times {
            let plain = times.partition_point(|&x| x <= t).saturating_sub(1).min(n - 2);
            prop_assert_eq!(tcb_core::track::segment_from(&times, t, hint), plain);
        }
        prop_assert_eq!(tcb_core::track::segment_from(&times, f64::NAN, hint), 0);
    }

    #[test]
    fn passes_through_every_key((t, v, c) in track3(8), rule in 0..4usize, ends in 0..3usize) {
        let settings = TrackSettings {
            tangent_rule: RULES[rule],
            ends: [Ends::Copy, Ends::Zero, Ends::Natural][ends],
            ..Default::default()
        };
        let track = Track::new(t.clone(), v.clone(), keys(&c), &settings).unwrap();
        for (time, value) in t.iter().zip(&v) {
            prop_assert!(close(track.sample(*time), *value, 1e-6), "{} {}", track.sample(*time), value);
        }
    }

    #[test]
    fn cyclic_passes_through_every_key_and_loops((t, mut v, c) in track3(8), rule in 0..4usize) {
        prop_assume!(t.len() >= 3);
        let n = v.len();
        v[n - 1] = v[0];
        let settings = TrackSettings {
            tangent_rule: RULES[rule],
            ends: Ends::Cyclic,
            post: Extrapolation::Repeat,
            ..Default::default()
        };
        let track = Track::new(t.clone(), v.clone(), keys(&c), &settings).unwrap();
        for (time, value) in t.iter().zip(&v) {
            prop_assert!(close(track.sample(*time), *value, 1e-6));
        }
        // Velocity is continuous across the loop point: leaving key 0 equals
        // leaving key n-1 into the next cycle (its key-0 tangent), and
        // arriving at key n-1 uses the same tangent pair.
        let (_, leave) = track.sample_with_velocity(t[0]);
        let (_, wrap) = track.sample_with_velocity(t[n - 1] + 1e-12);
        prop_assert!(close(leave, wrap, 1e-4));
    }

    #[test]
    fn adjusted_keeps_speed_at_zero_continuity((t, v, c) in track3(8)) {
        prop_assume!(t.len() >= 3);
        let c: Vec<Tcb> = c.iter().map(|k| Tcb::new(k.tension, 0.0, k.bias)).collect();
        let track = Track::new(t.clone(), v, keys(&c), &TrackSettings::default()).unwrap();
        for k in 1..t.len() - 1 {
            let (d_in, d_out) = (t[k] - t[k - 1], t[k + 1] - t[k]);
            let tk = track.tangents()[k];
            let ti = tk.incoming.norm() / d_in;
            let to = tk.outgoing.norm() / d_out;
            prop_assert!((ti - to).abs() <= 1e-5 * ti.max(to).max(1.0), "{ti} {to}");
        }
    }

    #[test]
    fn match_speed_gives_equal_lengths((t, v, c) in track3(8), rule in 0..4usize) {
        prop_assume!(t.len() >= 3);
        let settings = TrackSettings {
            tangent_rule: RULES[rule],
            match_speed: true,
            ..Default::default()
        };
        let track = Track::new(t.clone(), v, keys(&c), &settings).unwrap();
        for k in 1..t.len() - 1 {
            let tk = track.tangents()[k];
            let ti = tk.incoming.norm() / (t[k] - t[k - 1]);
            let to = tk.outgoing.norm() / (t[k + 1] - t[k]);
            prop_assert!((ti - to).abs() <= 1e-5 * ti.max(to).max(1.0), "{ti} {to}");
        }
    }

    #[test]
    fn one_tension_is_the_cardinal_spline(n in 3..8usize, tension in -1.0..1.0f64, seed in prop::collection::vec(vec3(), 8), dt in 0.1..2.0f64) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let v = seed[..n].to_vec();
        let settings = TrackSettings { tangent_rule: TangentRule::Uniform, ..Default::default() };
        let track = Track::new(t.clone(), v.clone(), keys(&vec![Tcb::new(tension, 0.0, 0.0); n]), &settings).unwrap();
        let a = ((1.0 - tension) / 2.0) as f32;
        // Interior segments: tangents a (P_{k+1} - P_{k-1}).
        for k in 1..n - 2 {
            let m0 = (v[k + 1] - v[k - 1]) * a;
            let m1 = (v[k + 2] - v[k]) * a;
            for s in [0.25f32, 0.5, 0.8] {
                let h = tcb_core::simd::basis::hermite_basis(s);
                let want = v[k] * h[0] + v[k + 1] * h[1] + m0 * h[2] + m1 * h[3];
                let got = track.sample(t[k] + dt * s as f64);
                prop_assert!(close(got, want, 1e-5), "{got} {want}");
            }
        }
    }

    #[test]
    fn corner_continuity_with_uniform_is_linear((t, v, _) in track3(8)) {
        let settings = TrackSettings { tangent_rule: TangentRule::Uniform, ..Default::default() };
        let track = Track::new(t.clone(), v.clone(), keys(&vec![Tcb::LINEAR; t.len()]), &settings).unwrap();
        for k in 0..t.len() - 1 {
            for u in [0.1, 0.5, 0.9] {
                let want = v[k].lerp(v[k + 1], u as f32);
                prop_assert!(close(track.sample(t[k] + u * (t[k + 1] - t[k])), want, 1e-5));
            }
        }
    }

    #[test]
    fn parabolic_reproduces_quadratics(t in (4..8usize).prop_flat_map(times), a in vec3(), b in vec3(), c in vec3()) {
        let f = |x: f64| a * (x * x) as f32 + b * x as f32 + c;
        let values: Vec<Vec3> = t.iter().map(|&x| f(x)).collect();
        let settings = TrackSettings { tangent_rule: TangentRule::Parabolic, ..Default::default() };
        let track = Track::new(t.clone(), values, vec![], &settings).unwrap();
        for k in 1..t.len() - 2 {
            for u in [0.2, 0.5, 0.7] {
                let x = t[k] + u * (t[k + 1] - t[k]);
                let scale = 1.0 + (a.abs().max_element() * (x * x) as f32) + b.abs().max_element() * x.abs() as f32;
                prop_assert!((track.sample(x) - f(x)).abs().max_element() <= 2e-5 * scale, "{} {}", track.sample(x), f(x));
            }
        }
    }

    #[test]
    fn repeat_far_away_equals_the_wrapped_time((t, v, c) in track3(6), frac in 0.0..1.0f64, cycles in 1..1_000_000u32) {
        let settings = TrackSettings { pre: Extrapolation::Repeat, post: Extrapolation::Repeat, ..Default::default() };
        let track = Track::new(t.clone(), v, keys(&c), &settings).unwrap();
        let len = t[t.len() - 1] - t[0];
        let inside = t[0] + frac * len;
        let far = inside + cycles as f64 * len;
        // f64 keeps about 1e-16 relative: the wrapped time differs by at most
        // far * 2^-52, well under the tolerance of the f32 result.
        prop_assert!(close(track.sample(far), track.sample(inside), 1e-4));
        prop_assert!(close(track.sample(inside - cycles as f64 * len), track.sample(inside), 1e-4));
    }

    #[test]
    fn repeat_at_a_million_seconds(frac in 0.0..1.0f64) {
        let t = vec![0.0, 0.5, 1.25, 2.0];
        let v = vec![Vec2::ZERO, Vec2::new(1.0, 2.0), Vec2::new(2.0, 0.0), Vec2::new(3.0, 1.0)];
        let settings = TrackSettings { post: Extrapolation::Repeat, ..Default::default() };
        let track = Track::new(t, v, vec![], &settings).unwrap();
        // 1e6 is 500000 whole periods of 2 s.
        let a = track.sample(1e6 + 2.0 * frac);
        let b = track.sample(2.0 * frac);
        prop_assert!((a - b).abs().max_element() < 1e-5, "{a} {b}");
    }

    #[test]
    fn any_time_never_panics_and_is_finite((t, v, c) in track3(6), time in prop::num::f64::ANY, pre in 0..6usize, post in 0..6usize) {
        let settings = TrackSettings { pre: Extrapolation::ALL[pre], post: Extrapolation::ALL[post], ..Default::default() };
        let track = Track::new(t, v, keys(&c), &settings).unwrap();
        let (value, velocity) = track.sample_with_velocity(time);
        if time.abs() < 1e20 {
            prop_assert!(value.is_finite() && velocity.is_finite());
        }
    }
}

/// Random unit quaternions near each other's hemisphere or not.
fn quats(n: usize) -> impl Strategy<Value = Vec<Quat>> {
    prop::collection::vec(
        (-1.0..1.0f32, -1.0..1.0f32, -1.0..1.0f32, -1.0..1.0f32)
            .prop_filter("non-zero", |(x, y, z, w)| {
                x * x + y * y + z * z + w * w > 0.01
            })
            .prop_map(|(x, y, z, w)| Quat::from_xyzw(x, y, z, w).normalize()),
        n,
    )
}

proptest! {
    #![proptest_config(proptest_config(100))]

    #[test]
    fn rotations_are_unit_and_pass_through_keys(
        (t, q, c) in (2..7usize).prop_flat_map(|n| (times(n), quats(n), prop::collection::vec(tcb(), n))),
        hermite in any::<bool>(), rule in 0..4usize, time in -10.0..20.0f64,
    ) {
        let settings = TrackSettings {
            rotation: if hermite { RotationMode::Hermite } else { RotationMode::Squad },
            tangent_rule: RULES[rule],
            ..Default::default()
        };
        let track = RotationTrack::new(t.clone(), q.clone(), keys(&c), &settings).unwrap();
        let r = track.sample(time);
        prop_assert!((r.length() - 1.0).abs() < 1e-5);
        for (time, want) in t.iter().zip(&q) {
            prop_assert!(quat_close(track.sample(*time), *want, 1e-5));
        }
    }

    #[test]
    fn squad_with_default_tcb_on_even_keys_is_shoemake(q in quats(6), dt in 0.1..2.0f64, s in 0.0..1.0f64) {
        let t: Vec<f64> = (0..6).map(|k| k as f64 * dt).collect();
        let track = RotationTrack::new(t.clone(), q, vec![], &TrackSettings::default()).unwrap();
        let qs: Vec<DQuat> = track.values().iter().map(|q| q.as_dquat()).collect();
        // Shoemake: a_k = q_k exp(-(log(q_k^-1 q_{k+1}) + log(q_k^-1 q_{k-1})) / 4)
        let inner = |k: usize| {
            let l = quat_log(qs[k].conjugate() * qs[k + 1]) + quat_log(qs[k].conjugate() * qs[k - 1]);
            qs[k] * quat_exp(-l / 4.0)
        };
        for k in 1..4 {
            let want = squad(qs[k], qs[k + 1], inner(k), inner(k + 1), s);
            let got = track.sample(t[k] + s * dt).as_dquat();
            let (a, b) = (DVec4::from(got), DVec4::from(want));
            prop_assert!((a - b).length().min((a + b).length()) < 1e-5);
        }
    }
}

/// The paper prints eq. 10 with the two factors swapped: DS scaled by
/// 2 D+/(D- + D+) and DD by 2 D-/(D- + D+). On uneven keys that makes the
/// speed jump at a key with c = 0, which is why the contract swaps them back.
#[test]
fn printed_eq_10_would_make_speed_jump() {
    let (d_in, d_out) = (1.0, 3.0);
    let (a, b) = (Vec3::new(1.0, 2.0, 0.0), Vec3::new(3.0, -1.0, 1.0));
    let tcb = Tcb::new(0.2, 0.0, 0.3);
    // Ours.
    let (ds, dd) = ChordWeights::new(TangentRule::Adjusted, tcb, d_in, d_out).apply(a, b);
    assert!((ds.norm() / d_in - dd.norm() / d_out).abs() < 1e-6);
    // As printed: the factors swapped.
    let (ds_u, dd_u) = ChordWeights::new(TangentRule::Uniform, tcb, d_in, d_out).apply(a, b);
    let printed_ds = ds_u.scale(2.0 * d_out / (d_in + d_out));
    let printed_dd = dd_u.scale(2.0 * d_in / (d_in + d_out));
    let (ti, to) = (printed_ds.norm() / d_in, printed_dd.norm() / d_out);
    assert!((ti / to - 9.0).abs() < 1e-5, "speed ratio {}", ti / to);
}
