//! Export to glTF 2.0 (`.gltf` with an embedded buffer, or `.glb`).
//!
//! Tracks named `<node>.translation|rotation|scale` and
//! `<node>.weights.<i>` become animation channels of one flat node per
//! `<node>`. What glTF can express is written exactly:
//!
//! - vector tracks and `hermite` rotations as `CUBICSPLINE`, with
//!   `out_k = DD_k / D_k` and `in_k+1 = DS_k+1 / D_k` (time-unit tangents);
//! - tracks whose every segment is `step` as `STEP`;
//! - rotations whose every segment is `linear` (slerp), without ease, as
//!   `LINEAR`.
//!
//! The rest (squad, ease, slerp segments of hermite rotations, `step`
//! segments inside a curve) is resampled: each segment is split into 1, 2,
//! 4, ... 64 pieces until the cubic through the reference's values and
//! derivatives is within the requested error of the reference, measured at
//! 8 points per piece; the error reached is reported per track. glTF holds
//! the end values outside the keys, so other `pre`/`post` modes are
//! reported as notes.

use crate::Error;
use crate::gltf_import::base64_encode;
use serde_json::{Value, json};
use std::path::Path;
use tcb_core::{Extrapolation, Interp, Track, TrackData, Value as TcbValue};

/// How one track was written.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackExport {
    /// The track.
    pub name: String,
    /// `None` when exact; else the largest difference from the reference
    /// measured on the resampled curve (relative to max(1, |value|)).
    pub resampled_error: Option<f64>,
}

/// What [`export`] did.
#[derive(Clone, Debug, Default)]
pub struct ExportReport {
    /// Every track, in clip order.
    pub tracks: Vec<TrackExport>,
    /// What glTF cannot hold at all (extrapolation modes).
    pub notes: Vec<String>,
}

impl ExportReport {
    /// The largest resampling error (0 when everything is exact).
    pub fn max_error(&self) -> f64 {
        self.tracks
            .iter()
            .filter_map(|t| t.resampled_error)
            .fold(0.0, f64::max)
    }
}

/// One sampler's data.
struct Sampler {
    times: Vec<f32>,
    interpolation: &'static str,
    /// Components per output element (3, 4, or the number of morph targets).
    width: usize,
    /// Output elements (for CUBICSPLINE: in, value, out per key).
    output: Vec<f32>,
    kind: &'static str,
}

/// Keys with values and time-unit tangents, `dim` components each.
struct Cubic {
    times: Vec<f64>,
    values: Vec<Vec<f32>>,
    tin: Vec<Vec<f32>>,
    tout: Vec<Vec<f32>>,
}

fn exact_cubic<V: TcbValue>(t: &Track<V>) -> Cubic {
    let times = t.times().to_vec();
    let n = times.len();
    let arr = |v: V| v.to_array()[..V::DIM].to_vec();
    let mut tin = vec![vec![0.0; V::DIM]; n];
    let mut tout = vec![vec![0.0; V::DIM]; n];
    for (k, s) in t.segments().iter().enumerate() {
        // glTF key times are f32, and readers take the span from those:
        // divide by that span so that `tangent * span` gives M back.
        let d = (f64::from(times[k + 1] as f32) - f64::from(times[k] as f32)) as f32;
        tout[k] = arr(s.m0).iter().map(|m| m / d).collect();
        tin[k + 1] = arr(s.m1).iter().map(|m| m / d).collect();
    }
    tin[0] = tout[0].clone();
    tout[n - 1] = tin[n - 1].clone();
    Cubic {
        values: t.values().iter().map(|v| arr(*v)).collect(),
        times,
        tin,
        tout,
    }
}

fn exact_shape<V: TcbValue>(t: &Track<V>) -> Shape {
    let segs = t.segments();
    if segs.iter().all(|s| s.interp == Interp::Step) {
        Shape::Step
    } else if segs
        .iter()
        .all(|s| s.ease.is_none() && s.interp != Interp::Step)
    {
        Shape::Cubic
    } else {
        Shape::Resample
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Shape {
    Step,
    Linear,
    Cubic,
    Resample,
}

/// Hermite on one component over `[0, 1]` with time-unit tangents and span `d`.
fn hermite(p0: f32, p1: f32, m0: f32, m1: f32, d: f32, u: f32) -> f32 {
    let h = tcb_core::basis::hermite_basis(u);
    h[0] * p0 + h[1] * p1 + h[2] * m0 * d + h[3] * m1 * d
}

/// Value, in tangent and out tangent at a knot.
type Knot = (Vec<f32>, Vec<f32>, Vec<f32>);

/// Resample `data` (dim components) as a cubic within `max_error`.
fn resample(data: &TrackData, max_error: f64) -> (Cubic, f64) {
    let dim = data.kind().dim();
    let rotation = matches!(data, TrackData::Quat(_));
    let keys = data.times().to_vec();
    let sample = |t: f64| {
        let (mut v, mut d) = (vec![0.0f32; dim], vec![0.0f32; dim]);
        data.sample_into(t, &mut v, Some(&mut d));
        (v, d)
    };
    let (v0, d0) = sample(keys[0]);
    let mut out = Cubic {
        times: vec![keys[0]],
        values: vec![v0],
        tin: vec![d0.clone()],
        tout: vec![d0],
    };
    let mut worst = 0.0f64;
    for k in 0..keys.len() - 1 {
        let (a, b) = (keys[k], keys[k + 1]);
        let mut best: Option<(Vec<f64>, Vec<Knot>, f64)> = None;
        let mut pieces = 1;
        while pieces <= 64 {
            let knots: Vec<f64> = (0..=pieces)
                .map(|j| a + (b - a) * j as f64 / pieces as f64)
                .collect();
            // (value, in tangent, out tangent) at each knot. The in tangent at
            // b is the left derivative; its out tangent is replaced by the
            // next segment's first knot (and at the last key the reference's
            // velocity is already the left derivative).
            let at: Vec<_> = knots
                .iter()
                .enumerate()
                .map(|(j, &t)| {
                    let (v, d) = sample(t);
                    let din = if j == pieces {
                        sample(b - (b - a) * 1e-7).1
                    } else {
                        d.clone()
                    };
                    (v, din, d)
                })
                .collect();
            let mut err = 0.0f64;
            for j in 0..pieces {
                let d = (knots[j + 1] - knots[j]) as f32;
                for i in 1..8 {
                    let u = i as f32 / 8.0;
                    let t = knots[j] + f64::from(u) * (knots[j + 1] - knots[j]);
                    let mut got: Vec<f32> = (0..dim)
                        .map(|c| {
                            hermite(at[j].0[c], at[j + 1].0[c], at[j].2[c], at[j + 1].1[c], d, u)
                        })
                        .collect();
                    if rotation {
                        let l = got.iter().map(|x| x * x).sum::<f32>().sqrt();
                        got.iter_mut().for_each(|x| *x /= l);
                    }
                    let want = sample(t).0;
                    let diff = |s: f32| {
                        want.iter()
                            .zip(&got)
                            .map(|(w, g)| f64::from((w - s * g).abs() / w.abs().max(1.0)))
                            .fold(0.0, f64::max)
                    };
                    err = err.max(if rotation {
                        diff(1.0).min(diff(-1.0))
                    } else {
                        diff(1.0)
                    });
                }
            }
            let better = best.as_ref().is_none_or(|b| err < b.2);
            if better {
                best = Some((knots, at, err));
            }
            if err <= max_error {
                break;
            }
            pieces *= 2;
        }
        let (knots, at, err) = best.expect("at least one try");
        worst = worst.max(err);
        // The knot at `a` is already there: set its out tangent, add the rest.
        let last = out.times.len() - 1;
        out.tout[last] = at[0].2.clone();
        for (t, (v, din, dout)) in knots.into_iter().zip(at).skip(1) {
            out.times.push(t);
            out.values.push(v);
            out.tin.push(din);
            out.tout.push(dout);
        }
    }
    (out, worst)
}

fn cubic_sampler(c: &Cubic, kind: &'static str) -> Sampler {
    let width = c.values[0].len();
    let mut output = Vec::with_capacity(c.times.len() * width * 3);
    for k in 0..c.times.len() {
        output.extend_from_slice(&c.tin[k]);
        output.extend_from_slice(&c.values[k]);
        output.extend_from_slice(&c.tout[k]);
    }
    Sampler {
        times: c.times.iter().map(|&t| t as f32).collect(),
        interpolation: "CUBICSPLINE",
        width,
        output,
        kind,
    }
}

/// Where a track goes: node name and glTF path (and the morph target).
fn target(name: &str, data: &TrackData) -> Result<(String, &'static str, usize), String> {
    use tcb_core::TrackKind::*;
    let kind = data.kind();
    for (suffix, path, want) in [
        (".translation", "translation", Vec3),
        (".rotation", "rotation", Quat),
        (".scale", "scale", Vec3),
    ] {
        if let Some(node) = name.strip_suffix(suffix) {
            if kind != want {
                return Err(format!(
                    "track '{name}' is {kind}; glTF {path} needs {want}"
                ));
            }
            return Ok((node.to_string(), path, 0));
        }
    }
    if let Some((node, i)) = name.rsplit_once(".weights.")
        && let Ok(i) = i.parse::<usize>()
    {
        if kind != Scalar {
            return Err(format!(
                "track '{name}' is {kind}; morph weights are scalar"
            ));
        }
        return Ok((node.to_string(), "weights", i));
    }
    Err(format!(
        "track '{name}' ({kind}) has no glTF target: glTF animates <node>.translation, <node>.rotation, <node>.scale and <node>.weights.<i>"
    ))
}

/// Export `clip` to glTF; `.glb` when `binary`. Returns the file bytes and
/// the report.
pub fn export(
    clip: &tcb_core::Clip,
    binary: bool,
    max_error: f64,
) -> Result<(Vec<u8>, ExportReport), Error> {
    let mut report = ExportReport::default();
    let mut nodes: Vec<String> = Vec::new();
    // (node, path, sampler)
    let mut channels: Vec<(usize, &'static str, Sampler)> = Vec::new();
    // Weight tracks per node: (target index, track index).
    let mut weights: Vec<(usize, Vec<(usize, usize)>)> = Vec::new();
    for (ti, t) in clip.tracks.iter().enumerate() {
        let (node, path, morph) = target(&t.name, &t.data).map_err(Error::import)?;
        let ni = match nodes.iter().position(|n| *n == node) {
            Some(i) => i,
            None => {
                nodes.push(node);
                nodes.len() - 1
            }
        };
        let (pre, post) = match &t.data {
            TrackData::Quat(r) => (r.settings().pre, r.settings().post),
            TrackData::Scalar(x) => (x.settings().pre, x.settings().post),
            TrackData::Vec2(x) => (x.settings().pre, x.settings().post),
            TrackData::Vec3(x) => (x.settings().pre, x.settings().post),
            TrackData::Vec4(x) => (x.settings().pre, x.settings().post),
        };
        for (side, mode) in [("pre", pre), ("post", post)] {
            if mode != Extrapolation::Constant {
                report.notes.push(format!(
                    "track '{}': {side} '{}' is not expressible; glTF holds the end value",
                    t.name,
                    mode.name()
                ));
            }
        }
        if path == "weights" {
            match weights.iter_mut().find(|w| w.0 == ni) {
                Some(w) => w.1.push((morph, ti)),
                None => weights.push((ni, vec![(morph, ti)])),
            }
            continue;
        }
        let (sampler, err) = track_sampler(&t.data, max_error);
        report.tracks.push(TrackExport {
            name: t.name.clone(),
            resampled_error: err,
        });
        channels.push((ni, path, sampler));
    }
    for (ni, mut list) in weights {
        list.sort();
        if list.iter().enumerate().any(|(i, (m, _))| *m != i) {
            return Err(Error::import(format!(
                "node '{}': weight tracks must be numbered 0, 1, 2, ... without gaps or repeats",
                nodes[ni]
            )));
        }
        let per: Vec<(Sampler, Option<f64>)> = list
            .iter()
            .map(|(_, ti)| track_sampler(&clip.tracks[*ti].data, max_error))
            .collect();
        if per
            .iter()
            .any(|(s, _)| s.times != per[0].0.times || s.interpolation != per[0].0.interpolation)
        {
            return Err(Error::import(format!(
                "node '{}': glTF stores all morph weights of a node in one sampler; its weight tracks need the same key times and the same exactness (all exact or all resampled the same way)",
                nodes[ni]
            )));
        }
        for ((_, ti), (_, e)) in list.iter().zip(&per) {
            report.tracks.push(TrackExport {
                name: clip.tracks[*ti].name.clone(),
                resampled_error: *e,
            });
        }
        channels.push((
            ni,
            "weights",
            merge(&per.iter().map(|p| &p.0).collect::<Vec<_>>()),
        ));
    }
    let bytes = write(&clip.name, &nodes, &channels, binary);
    Ok((bytes, report))
}

fn track_sampler(data: &TrackData, max_error: f64) -> (Sampler, Option<f64>) {
    let kind = match data.kind().dim() {
        1 => "SCALAR",
        3 => "VEC3",
        _ => "VEC4",
    };
    let shape = match data {
        TrackData::Scalar(t) => exact_shape(t),
        TrackData::Vec2(t) => exact_shape(t),
        TrackData::Vec3(t) => exact_shape(t),
        TrackData::Vec4(t) => exact_shape(t),
        TrackData::Quat(r) => {
            let interps = &r.interps()[..r.interps().len() - 1];
            let eased = r.eases().iter().any(|e| !e.is_none());
            match r.hermite_track() {
                Some(h) if !interps.contains(&Interp::Linear) => exact_shape(h),
                _ if interps.iter().all(|i| *i == Interp::Step) => Shape::Step,
                // glTF LINEAR is slerp (shortest path; the keys are already
                // on one hemisphere, so the same path).
                _ if !eased && interps.iter().all(|i| *i == Interp::Linear) => Shape::Linear,
                _ => Shape::Resample,
            }
        }
    };
    match shape {
        Shape::Step | Shape::Linear => {
            let dim = data.kind().dim();
            let mut output = Vec::new();
            let mut v = vec![0.0f32; dim];
            for &t in data.times() {
                data.sample_into(t, &mut v, None);
                output.extend_from_slice(&v);
            }
            let sampler = Sampler {
                times: data.times().iter().map(|&t| t as f32).collect(),
                interpolation: if shape == Shape::Step {
                    "STEP"
                } else {
                    "LINEAR"
                },
                width: dim,
                output,
                kind,
            };
            (sampler, None)
        }
        Shape::Cubic => {
            let c = match data {
                TrackData::Scalar(t) => exact_cubic(t),
                TrackData::Vec2(t) => exact_cubic(t),
                TrackData::Vec3(t) => exact_cubic(t),
                TrackData::Vec4(t) => exact_cubic(t),
                TrackData::Quat(r) => exact_cubic(r.hermite_track().expect("checked above")),
            };
            (cubic_sampler(&c, kind), None)
        }
        Shape::Resample => {
            let (c, err) = resample(data, max_error);
            (cubic_sampler(&c, kind), Some(err))
        }
    }
}

fn merge(samplers: &[&Sampler]) -> Sampler {
    let targets = samplers.len();
    let per_key = if samplers[0].interpolation == "CUBICSPLINE" {
        3
    } else {
        1
    };
    let elements = samplers[0].times.len() * per_key;
    let mut output = Vec::with_capacity(elements * targets);
    for e in 0..elements {
        for s in samplers {
            output.push(s.output[e]);
        }
    }
    Sampler {
        times: samplers[0].times.clone(),
        interpolation: samplers[0].interpolation,
        width: 1,
        output,
        kind: "SCALAR",
    }
}

fn write(
    name: &str,
    nodes: &[String],
    channels: &[(usize, &'static str, Sampler)],
    binary: bool,
) -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push = |data: &[f32], count: usize, kind: &str, minmax: bool| -> usize {
        let offset = bin.len();
        for x in data {
            bin.extend_from_slice(&x.to_le_bytes());
        }
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": data.len() * 4}));
        let mut a = json!({"bufferView": views.len() - 1, "componentType": 5126, "count": count, "type": kind});
        if minmax {
            let min = data.iter().copied().fold(f32::INFINITY, f32::min);
            let max = data.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            a["min"] = json!([min]);
            a["max"] = json!([max]);
        }
        accessors.push(a);
        accessors.len() - 1
    };
    let mut samplers = Vec::new();
    let mut anim_channels = Vec::new();
    for (node, path, s) in channels {
        let input = push(&s.times, s.times.len(), "SCALAR", true);
        let count = s.output.len() / if s.kind == "SCALAR" { 1 } else { s.width };
        let output = push(&s.output, count, s.kind, false);
        samplers.push(json!({"input": input, "output": output, "interpolation": s.interpolation}));
        anim_channels
            .push(json!({"sampler": samplers.len() - 1, "target": {"node": node, "path": path}}));
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "tcb export"},
        "scene": 0,
        "scenes": [{"nodes": (0..nodes.len()).collect::<Vec<_>>()}],
        "nodes": nodes.iter().map(|n| json!({"name": n})).collect::<Vec<Value>>(),
        "bufferViews": views,
        "accessors": accessors,
        "animations": [{"name": name, "channels": anim_channels, "samplers": samplers}],
    });
    if binary {
        doc["buffers"] = json!([{"byteLength": bin.len()}]);
        let mut json_bytes = serde_json::to_vec(&doc).expect("serializable");
        while !json_bytes.len().is_multiple_of(4) {
            json_bytes.push(b' ');
        }
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(json_bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json_bytes);
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
        out
    } else {
        doc["buffers"] = json!([{
            "byteLength": bin.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64_encode(&bin)),
        }]);
        let mut text = serde_json::to_vec_pretty(&doc).expect("serializable");
        text.push(b'\n');
        text
    }
}

/// Export to `path` (`.glb` binary, else `.gltf`), written atomically.
pub fn export_file(
    clip: &tcb_core::Clip,
    path: &Path,
    max_error: f64,
) -> Result<ExportReport, Error> {
    let binary = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb"));
    let (bytes, report) = export(clip, binary, max_error).map_err(|e| e.in_file(path))?;
    crate::write_atomically(path, &bytes)?;
    Ok(report)
}
