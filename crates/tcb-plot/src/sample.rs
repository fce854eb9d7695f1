//! What a plot reads from a clip: values, velocities, speeds, rotations as
//! angle and axis, tangent handles, and the times to sample them at.

use tcb_core::{NamedTrack, TrackData, TrackKind};

/// A point of a chart.
pub(crate) type Point = (f64, f64);

/// Sample times over `[a, b]`: `n` even steps plus every key inside, so
/// corners (continuity -1, steps) are drawn sharp.
pub(crate) fn sample_times(tracks: &[&NamedTrack], a: f64, b: f64, n: usize) -> Vec<f64> {
    let mut t: Vec<f64> = (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect();
    for tr in tracks {
        for &k in tr.data.times() {
            if k > a && k < b {
                // Both sides of a key, for steps.
                t.push(k);
                t.push(k - (b - a) * 1e-7);
            }
        }
    }
    t.sort_by(f64::total_cmp);
    t.dedup();
    t
}

/// Value and velocity of a track at `t` (4 slots; `dim` used).
pub(crate) fn at(data: &TrackData, t: f64) -> ([f32; 4], [f32; 4]) {
    let (mut v, mut d) = ([0.0f32; 4], [0.0f32; 4]);
    let dim = data.kind().dim();
    data.sample_into(t, &mut v[..dim], Some(&mut d[..dim]));
    (v, d)
}

/// A rotation's angle (degrees, 0 to 180) and unit axis, from its `log`
/// on the `w >= 0` hemisphere (`v th/2`).
pub(crate) fn angle_axis(q: [f32; 4]) -> (f64, [f64; 3]) {
    let q = glam::Quat::from_array(q).as_dquat();
    let log = tcb_core::rotation::quat_log(if q.w < 0.0 { -q } else { q });
    let half = log.length();
    let axis = if half > 1e-12 {
        (log / half).to_array()
    } else {
        [0.0; 3]
    };
    ((2.0 * half).to_degrees(), axis)
}

/// Angular speed (degrees per second) of a unit quaternion with component
/// derivative `d` ([`tcb_core::quat::angular_velocity`]).
fn angular_speed(q: [f32; 4], d: [f32; 4]) -> f64 {
    let w = tcb_core::quat::angular_velocity(&q.map(f64::from), &d.map(f64::from));
    glam::DVec3::from_array(w).length().to_degrees()
}

/// The speed of a track at `t`: the length of its velocity, or for a
/// rotation its angular speed in degrees per second.
pub(crate) fn speed(data: &TrackData, t: f64) -> f64 {
    let (v, d) = at(data, t);
    if data.kind() == TrackKind::Quat {
        angular_speed(v, d)
    } else {
        d.iter().map(|x| f64::from(*x).powi(2)).sum::<f64>().sqrt()
    }
}

/// Tangent handles of a vector track's segments inside `[from, to]`, as
/// Bezier control points: `P_k + M0 / 3` and `P_k+1 - M1 / 3`.
pub(crate) fn handles(
    data: &TrackData,
    [a, b]: [usize; 2],
    from: f64,
    to: f64,
) -> Vec<(Point, Point)> {
    fn of<V: tcb_core::Value>(
        t: &tcb_core::Track<V>,
        [a, b]: [usize; 2],
        from: f64,
        to: f64,
    ) -> Vec<(Point, Point)> {
        let xy = |v: V| {
            let v = v.to_array();
            (f64::from(v[a]), f64::from(v[b]))
        };
        let mut out = Vec::new();
        for (k, s) in t.segments().iter().enumerate() {
            if s.interp != tcb_core::Interp::Curve {
                continue;
            }
            let (t0, t1) = (t.times()[k], t.times()[k + 1]);
            let (p0, p1, m0, m1) = (xy(s.p0), xy(s.p1), xy(s.m0), xy(s.m1));
            if (from..=to).contains(&t0) {
                out.push((p0, (p0.0 + m0.0 / 3.0, p0.1 + m0.1 / 3.0)));
            }
            if (from..=to).contains(&t1) {
                out.push((p1, (p1.0 - m1.0 / 3.0, p1.1 - m1.1 / 3.0)));
            }
        }
        out
    }
    match data {
        TrackData::Vec2(t) => of(t, [a, b], from, to),
        TrackData::Vec3(t) => of(t, [a, b], from, to),
        TrackData::Vec4(t) => of(t, [a, b], from, to),
        _ => Vec::new(),
    }
}
