//! Times that favour the edges (issue 29): a key time moved by a few f64
//! ulps or a few f32 steps, a hair inside a segment, the ends of f32's and
//! f64's ranges (±MAX, the smallest normals and subnormals), and now and
//! then anything at all (NaN and infinities included).

use arbitrary::{Arbitrary, Unstructured};

/// Extremes, each also taken a few ulps in.
const EXTREMES: [f64; 16] = [
    f64::MAX,
    -f64::MAX,
    f64::MIN_POSITIVE,
    -f64::MIN_POSITIVE,
    5e-324,
    -5e-324,
    f32::MAX as f64,
    -(f32::MAX as f64),
    f32::MIN_POSITIVE as f64,
    16_777_216.0,
    9_007_199_254_740_992.0,
    1e300,
    -1e300,
    1e38,
    0.0,
    -0.0,
];

/// `x` moved by `n` ulps (up for positive `n`), in f64.
pub fn ulps(x: f64, n: i32) -> f64 {
    let mut x = x;
    for _ in 0..n.unsigned_abs() {
        x = if n > 0 { x.next_up() } else { x.next_down() };
    }
    x
}

/// `x` rounded to f32 and moved by `n` f32 ulps, back in f64 (a time an
/// f32 pipeline could hold, next to one that it cannot).
pub fn f32_ulps(x: f64, n: i32) -> f64 {
    let mut y = x as f32;
    for _ in 0..n.unsigned_abs() {
        y = if n > 0 { y.next_up() } else { y.next_down() };
    }
    f64::from(y)
}

/// One time near `keys` (sorted key times; may be empty) or an extreme.
pub fn edge_time(u: &mut Unstructured, keys: &[f64]) -> arbitrary::Result<f64> {
    if u.is_empty() {
        return Err(arbitrary::Error::NotEnoughData);
    }
    let key = |u: &mut Unstructured| -> arbitrary::Result<(f64, usize)> {
        if keys.is_empty() {
            return Ok((0.0, 0));
        }
        let i = u.choose_index(keys.len())?;
        Ok((keys[i], i))
    };
    Ok(match u.int_in_range(0..=15u8)? {
        0 => f64::arbitrary(u)?,
        1 => *u.choose(&[f64::NAN, f64::INFINITY, f64::NEG_INFINITY])?,
        2 | 3 => ulps(*u.choose(&EXTREMES)?, i32::from(u.int_in_range(-4..=4i8)?)),
        4..=8 => ulps(key(u)?.0, i32::from(u.int_in_range(-6..=6i8)?)),
        9 | 10 => f32_ulps(key(u)?.0, i32::from(u.int_in_range(-3..=3i8)?)),
        11 | 12 => {
            // A fraction of the way to the next key, or just off either end.
            let (k, i) = key(u)?;
            let next = keys.get(i + 1).copied().unwrap_or(k + 1.0);
            let f = f64::from(u8::arbitrary(u)?) / 256.0;
            k + (next - k) * f
        }
        _ => f64::from(i16::arbitrary(u)?) / 1024.0,
    })
}

/// Up to `max` edge times.
pub fn edge_times(u: &mut Unstructured, keys: &[f64], max: usize) -> Vec<f64> {
    let mut times = Vec::new();
    while times.len() < max {
        match edge_time(u, keys) {
            Ok(t) => times.push(t),
            Err(_) => break,
        }
    }
    times
}
