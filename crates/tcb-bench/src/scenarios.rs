//! The scenarios, shared by the report and the criterion benches.
//!
//! | name | what |
//! |---|---|
//! | `character-hermite`, `character-squad` | the CMU clip (31 joints, 120 fps), 60 fps forward over the whole clip |
//! | `crowd` | 1,000 instances of it (hermite) at random phases, 60 frames |
//! | `wide` | 10,000 scalar channels on one key grid (61 keys), 60 fps over 2 s |
//! | `sparse` | 500 scalar tracks, each with its own random key times |
//! | `sparse-rotations` | 128 rotations (64 `hermite`, 64 `squad`), each with its own random key times |
//! | `character-quantized` | `character-hermite` compiled with 16-bit controls |
//! | `seek` | the CMU clip (hermite) at random times, as many as `character` |
//! | `sparse-seek` | `sparse` at random times, as many as `sparse` (every frame a seek of every lane) |
//! | `character-reduced` | the CMU clip (hermite) reduced by `tcb reduce` at the default shell tolerance, as `character` |
//! | `character-compressed` | the CMU clip packed by `tcb compress` at the default shell tolerance (a `.tcbc`), as `character` |
//! | `character-compressed-acl` | the same at ACL's default error target ([`ACL_TARGET`]) |

use crate::Rng;
use crate::baseline::Baseline;
use crate::peer::SplinesPeer;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tcb_core::{KeyParams, NamedTrack, RotationMode, Track, TrackData, TrackSettings};
use tcb_runtime::Instance;
use wide::f32x8;

/// The bundled CMU clip (`data/cmu-01_01.bvh`).
pub fn default_bvh() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/cmu-01_01.bvh")
}

/// A clip, how it is played, and every implementation's view of it.
pub struct Scenario {
    /// Name in the report.
    pub name: String,
    /// The validated clip (the tcb-core reference).
    pub source: tcb_core::SourceClip,
    /// The runtime's compiled clip.
    pub clip: Arc<tcb_runtime::Clip>,
    /// The scalar baseline.
    pub baseline: Baseline,
    /// The `splines` crate, where it computes the same curve (even keys, tcb 0).
    pub peer: Option<SplinesPeer>,
    /// Sample times of one pass.
    pub times: Vec<f64>,
    /// One phase per instance (`[0.0]` but for `crowd`).
    pub phases: Vec<f64>,
    /// Joints, for ns per joint.
    pub joints: Option<usize>,
    /// Whether to time the read limit (the same coefficient bytes summed).
    pub read_limit: bool,
    /// Whether to time instances in parallel with rayon.
    pub parallel: bool,
    /// A packed clip's `.tcbc` bytes.
    pub file_bytes: Option<usize>,
    /// A packed clip's load from those bytes, ms (the median of [`LOADS`]).
    pub load_ms: Option<f64>,
}

/// Loads of a packed clip from its bytes that [`Scenario::load_ms`] is
/// the median of.
pub const LOADS: usize = 11;

impl Scenario {
    fn new(name: impl Into<String>, source: tcb_core::SourceClip, times: Vec<f64>) -> Self {
        Scenario {
            name: name.into(),
            clip: Arc::new(tcb_runtime::Clip::compile(&source)),
            baseline: Baseline::new(&source),
            source,
            peer: None,
            times,
            phases: vec![0.0],
            joints: None,
            read_limit: false,
            parallel: false,
            file_bytes: None,
            load_ms: None,
        }
    }

    /// Values per sample (a quaternion counts 4).
    pub fn channels(&self) -> usize {
        self.source.channel_count()
    }

    /// Channel-samples in one pass.
    pub fn channel_samples(&self) -> f64 {
        (self.times.len() * self.phases.len() * self.channels()) as f64
    }

    /// The sample times and phases the slow references (the baseline and
    /// the `splines` crate) play: all of them, or with `max` set, the first
    /// instances and then the first frames, so that a pass has at most
    /// about `max` channel-samples (`--quick`: the baseline's pass over
    /// `crowd` would otherwise take seconds). Times are per channel-sample,
    /// so the shorter pass measures the same cost. The frames stay
    /// consecutive: every 4th frame instead made the baseline's binary
    /// searches mispredict and cost twice as much per sample.
    pub fn reference_subset(&self, max: Option<usize>) -> (Vec<f64>, Vec<f64>) {
        let (mut times, mut phases) = (self.times.clone(), self.phases.clone());
        if let Some(max) = max {
            let per_time = self.channels().max(1);
            phases.truncate((max / per_time).clamp(1, phases.len().max(1)));
            let per_frame = per_time * phases.len();
            times.truncate((max / per_frame).clamp(2, times.len().max(2)));
        }
        (times, phases)
    }

    /// One pass of the baseline over `times` at each of `phases`
    /// ([`Scenario::reference_subset`]).
    pub fn baseline_pass(&self, times: Vec<f64>, phases: Vec<f64>) -> impl FnMut() + '_ {
        let mut row = vec![0.0f32; self.baseline.channel_count()];
        move || {
            for &t in &times {
                for &p in &phases {
                    self.baseline.sample(t + p, &mut row);
                    black_box(&row);
                }
            }
        }
    }

    /// One instance per phase, without velocities.
    pub fn instances(&self) -> Vec<Instance> {
        self.phases
            .iter()
            .map(|_| Instance::new(self.clip.clone()))
            .collect()
    }

    /// One pass of the runtime, one thread.
    pub fn runtime_pass(&self) -> impl FnMut() + '_ {
        let mut instances = self.instances();
        move || {
            for &t in &self.times {
                for (inst, &p) in instances.iter_mut().zip(&self.phases) {
                    black_box(inst.sample(t + p));
                }
            }
        }
    }

    /// One pass of the runtime through [`tcb_runtime::batch::sample_all`]
    /// (rayon over the instances; the plain loop in a one-thread pool). The
    /// frame loop runs inside the pool, so the calling thread works rather
    /// than sleeping on every frame.
    pub fn parallel_pass(&self) -> impl FnMut() + '_ {
        let mut instances = self.instances();
        let mut at = vec![0.0; instances.len()];
        move || {
            rayon::scope(|_| {
                for &t in &self.times {
                    for (a, &p) in at.iter_mut().zip(&self.phases) {
                        *a = t + p;
                    }
                    tcb_runtime::batch::sample_all(&mut instances, &at)
                        .expect("a time per instance");
                    black_box(&instances);
                }
            })
        }
    }

    /// [`parallel_pass`](Self::parallel_pass) without a scheduler: the
    /// instances cut into one contiguous share per rayon thread, each share
    /// played through every frame on a thread of its own, with no
    /// synchronization between frames. Where rayon is as fast, what keeps
    /// both from the core count is the machine's (shared caches and
    /// memory, other tenants), not the scheduling.
    pub fn threads_pass(&self) -> impl FnMut() + '_ {
        let mut instances = self.instances();
        let threads = rayon::current_num_threads().max(1);
        move || {
            let share = instances.len().div_ceil(threads).max(1);
            std::thread::scope(|scope| {
                for (insts, phases) in instances.chunks_mut(share).zip(self.phases.chunks(share)) {
                    scope.spawn(move || {
                        for &t in &self.times {
                            for (inst, &p) in insts.iter_mut().zip(phases) {
                                black_box(inst.sample(t + p));
                            }
                        }
                    });
                }
            });
        }
    }

    /// One pass of the `splines` crate over `times`.
    pub fn peer_pass(&self, times: Vec<f64>) -> Option<impl FnMut() + '_> {
        let peer = self.peer.as_ref()?;
        let mut row = vec![0.0f32; peer.channel_count()];
        Some(move || {
            for &t in &times {
                peer.sample(t, &mut row);
                black_box(&row);
            }
        })
    }

    /// One pass of the read limit: per frame, the runtime's number of
    /// coefficient bytes (two neighbouring keys, which lie next to each
    /// other in memory) of an array laid out per key like the clip's,
    /// summed (no arithmetic beyond the adds).
    pub fn read_pass(&self) -> impl FnMut() + '_ {
        let per_frame = self.clip.bytes_per_frame() / 32;
        let per_key = per_frame / 2;
        let keys = self.source.key_times();
        let n = keys.len().max(2);
        let data: Vec<f32x8> = (0..(n + 4) * per_key)
            .map(|i| f32x8::splat(i as f32 * 1e-9))
            .collect();
        move || {
            for &t in &self.times {
                let k = keys
                    .partition_point(|&x| x <= t)
                    .saturating_sub(1)
                    .min(n - 2);
                let block = &data[k * per_key..k * per_key + per_frame];
                let mut acc = [f32x8::ZERO; 4];
                for c in block.chunks_exact(4) {
                    for i in 0..4 {
                        acc[i] += c[i];
                    }
                }
                black_box(acc[0] + acc[1] + acc[2] + acc[3]);
            }
        }
    }
}

/// Frame times `0, 1/fps, ...` up to `end`.
fn frames(end: f64, fps: f64) -> Vec<f64> {
    let n = (end * fps + 1e-9).floor() as usize;
    (0..=n).map(|i| i as f64 / fps).collect()
}

fn cmu(bvh: &Path, rotation: RotationMode) -> Result<(tcb_core::SourceClip, usize), tcb_io::Error> {
    let options = tcb_io::ImportOptions::default().rotation(rotation);
    let loaded = tcb_io::load_with(bvh, &options)?;
    let joints = animated_joints(&loaded);
    Ok((loaded.clip, joints))
}

/// Joints a clip animates, for ns per joint: the distinct `<joint>` of its
/// `<joint>.<part>` track names (End Sites and unanimated joints of a
/// skeleton do not count).
fn animated_joints(loaded: &tcb_io::Loaded) -> usize {
    let mut names: Vec<&str> = loaded
        .clip
        .tracks()
        .iter()
        .map(|t| t.name.rsplit_once('.').map_or(t.name.as_str(), |p| p.0))
        .collect();
    names.sort_unstable();
    names.dedup();
    names.len()
}

/// `character-hermite` or `character-squad`.
pub fn character(bvh: &Path, rotation: RotationMode) -> Result<Scenario, tcb_io::Error> {
    let (clip, joints) = cmu(bvh, rotation)?;
    let end = clip.time_range().map_or(0.0, |r| r.1);
    let name = match rotation {
        RotationMode::Hermite => "character-hermite",
        _ => "character-squad",
    };
    let mut s = Scenario::new(name, clip, frames(end, 60.0));
    s.joints = Some(joints);
    if rotation == RotationMode::Hermite {
        // Catmull-Rom on the components is hermite with tcb 0 on even keys.
        s.peer = Some(SplinesPeer::new(&s.source));
    }
    Ok(s)
}

/// `character-quantized`: `character-hermite` compiled with 16-bit
/// controls (`CompileOptions::quantize`).
pub fn character_quantized(bvh: &Path) -> Result<Scenario, tcb_io::Error> {
    let mut s = character(bvh, RotationMode::Hermite)?;
    s.name = "character-quantized".into();
    let options = tcb_runtime::CompileOptions::default().quantize(true);
    s.clip = Arc::new(tcb_runtime::Clip::compile_with(&s.source, &options));
    s.peer = None;
    Ok(s)
}

/// `character-reduced`: the hermite character after `tcb reduce` with the
/// contract's defaults (shell metric, `--knots track`), played like
/// `character-hermite`.
pub fn character_reduced(bvh: &Path) -> Result<Scenario, tcb_io::Error> {
    let (loaded, reduced) = reduce_cmu(bvh)?;
    let end = reduced.clip.time_range().map_or(0.0, |r| r.1);
    let mut s = Scenario::new("character-reduced", reduced.clip, frames(end, 60.0));
    s.joints = Some(animated_joints(&loaded));
    Ok(s)
}

/// ACL's default error target (0.01 cm at a 3 cm shell) in the CMU clip's
/// units, with 1 unit = 6.627 cm (its rest pose spans 25.65 units, a 1.7 m
/// figure): `(tolerance, shell)`.
pub const ACL_TARGET: (f64, f64) = (1.509e-3, 0.4527);

/// ACL 2.1's bytes for the CMU clip at [`ACL_TARGET`] (120 fps, its
/// defaults; `../shared/peers/acl/run.sh`, docs/benchmarks.md).
pub const ACL_CMU_BYTES: usize = 270_987;

/// `character-compressed` (`acl` false) or `character-compressed-acl`:
/// the hermite character packed by `tcb compress`, played like
/// `character-hermite` from the packed stream.
pub fn character_compressed(bvh: &Path, acl: bool) -> Result<Scenario, tcb_io::Error> {
    let packed = compress_cmu(bvh, acl)?;
    let name = if acl {
        "character-compressed-acl"
    } else {
        "character-compressed"
    };
    packed_scenario(name, packed, bvh)
}

/// The hermite character compressed by `tcb compress` (at ACL's target
/// with `acl`), what the compressed scenarios play and `--icount` hands to
/// the counted process as a file.
pub fn compress_cmu(bvh: &Path, acl: bool) -> Result<tcb_runtime::Packed, tcb_io::Error> {
    let options = tcb_io::ImportOptions::default().rotation(RotationMode::Hermite);
    let loaded = tcb_io::load_with(bvh, &options)?;
    let options = tcb_fit::CompressOptions::default()
        .tolerance(acl.then_some(ACL_TARGET.0))
        .shell(acl.then_some(ACL_TARGET.1));
    let c = tcb_fit::compress(&loaded.clip, loaded.skeleton.as_ref(), &options, &|_, _| {})
        .map_err(|e| tcb_io::Error::import(e.to_string()).in_file(bvh))?;
    Ok(c.packed)
}

/// A packed clip played at 60 fps forward over its keys; its baseline plays
/// the packed clip's reference (the dequantized keys).
fn packed_scenario(
    name: &str,
    packed: tcb_runtime::Packed,
    path: &Path,
) -> Result<Scenario, tcb_io::Error> {
    let err = |e: tcb_runtime::PackError| tcb_io::Error::import(e.to_string()).in_file(path);
    let bytes = packed.to_bytes();
    let file_bytes = bytes.len();
    let mut loads: Vec<f64> = (0..LOADS)
        .map(|_| {
            let t = std::time::Instant::now();
            let clip = tcb_runtime::Clip::from_bytes(std::hint::black_box(&bytes));
            let ms = t.elapsed().as_secs_f64() * 1e3;
            clip.map(|_| ms).map_err(err)
        })
        .collect::<Result<_, _>>()?;
    loads.sort_by(f64::total_cmp);
    let packed = Arc::new(packed);
    let source = packed.decode().and_then(|s| s.to_clip()).map_err(err)?;
    let clip = tcb_runtime::Clip::from_packed(packed).map_err(err)?;
    let mut joints: Vec<&str> = source
        .tracks()
        .iter()
        .map(|t| t.name.rsplit_once('.').map_or(t.name.as_str(), |p| p.0))
        .collect();
    joints.sort_unstable();
    joints.dedup();
    let joints = joints.len();
    let (start, end) = source.time_range().unwrap_or((0.0, 0.0));
    let times = frames(end - start, 60.0)
        .into_iter()
        .map(|t| t + start)
        .collect();
    let mut s = Scenario::new(name, source, times);
    s.clip = Arc::new(clip);
    s.joints = Some(joints);
    s.file_bytes = Some(file_bytes);
    s.load_ms = Some(loads[LOADS / 2]);
    Ok(s)
}

/// The clip `character-reduced` plays, as a document (what `--icount`
/// hands to the counted process).
pub fn reduced_doc(bvh: &Path) -> Result<tcb_io::ClipDoc, tcb_io::Error> {
    Ok(reduce_cmu(bvh)?.1.doc)
}

fn reduce_cmu(bvh: &Path) -> Result<(tcb_io::Loaded, tcb_fit::Reduced), tcb_io::Error> {
    let options = tcb_io::ImportOptions::default().rotation(RotationMode::Hermite);
    let loaded = tcb_io::load_with(bvh, &options)?;
    let input = tcb_fit::reduce::Input {
        doc: &loaded.doc,
        clip: &loaded.clip,
        skeleton: loaded.skeleton.as_ref(),
    };
    let reduced = tcb_fit::reduce(input, &tcb_fit::ReduceOptions::default(), &|_, _| {})
        .map_err(|e| tcb_io::Error::import(e.to_string()).in_file(bvh))?;
    Ok((loaded, reduced))
}

/// How [`file_with`] plays a user's clip.
#[derive(Clone, Debug)]
pub struct FileOptions {
    /// Frames per second, forward over the clip's keys.
    pub fps: f64,
    /// Instances at random phases (more than one adds the rayon column).
    pub instances: usize,
    /// Import options (BVH rotation mode, glTF animation).
    pub import: tcb_io::ImportOptions,
    /// How the runtime compiles it (quantization).
    pub compile: tcb_runtime::CompileOptions,
}

impl Default for FileOptions {
    fn default() -> Self {
        FileOptions {
            fps: 60.0,
            instances: 1,
            import: Default::default(),
            compile: Default::default(),
        }
    }
}

/// A clip file of the user's, played at 60 fps forward over its keys
/// (joints counted as `animated_joints` counts them).
pub fn file(path: &Path) -> Result<Scenario, tcb_io::Error> {
    file_with(path, &FileOptions::default())
}

/// [`file()`] with a frame rate, instance count and import options. With
/// several instances, each plays from its own random phase within the clip,
/// one second (or the whole clip, if shorter) per pass.
pub fn file_with(path: &Path, options: &FileOptions) -> Result<Scenario, tcb_io::Error> {
    let name = path
        .file_stem()
        .map_or("clip".into(), |s| s.to_string_lossy().into_owned());
    let mut s = if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("tcbc"))
    {
        // A packed clip plays its own stream: compile options do not apply.
        let err = |e: String| tcb_io::Error::import(e).in_file(path);
        if options.compile != tcb_runtime::CompileOptions::default() {
            return Err(err(
                "compile options (--quantize) do not apply to a packed clip".into(),
            ));
        }
        let bytes = std::fs::read(path).map_err(|e| err(e.to_string()))?;
        let packed = tcb_runtime::Packed::from_bytes(&bytes).map_err(|e| err(e.to_string()))?;
        packed_scenario(&name, packed, path)?
    } else {
        let loaded = tcb_io::load_with(path, &options.import)?;
        let joints = animated_joints(&loaded);
        let mut s = Scenario::new(name, loaded.clip, Vec::new());
        s.clip = Arc::new(tcb_runtime::Clip::compile_with(&s.source, &options.compile));
        s.joints = Some(joints);
        s
    };
    let (start, end) = s.source.time_range().unwrap_or((0.0, 0.0));
    let span = if options.instances > 1 {
        (end - start).min(1.0)
    } else {
        end - start
    };
    s.times = frames(span, options.fps)
        .into_iter()
        .map(|t| t + start)
        .collect();
    if options.instances > 1 {
        let mut rng = Rng(0xf11e);
        let room = (end - start - span).max(0.0);
        s.phases = (0..options.instances)
            .map(|_| rng.range(0.0, room))
            .collect();
        s.parallel = true;
    }
    Ok(s)
}

/// `seek`: the hermite character at random times.
pub fn seek(bvh: &Path) -> Result<Scenario, tcb_io::Error> {
    let (clip, joints) = cmu(bvh, RotationMode::Hermite)?;
    let end = clip.time_range().map_or(0.0, |r| r.1);
    let mut rng = Rng(0x5eec);
    let times = (0..frames(end, 60.0).len())
        .map(|_| rng.range(0.0, end))
        .collect();
    let mut s = Scenario::new("seek", clip, times);
    s.joints = Some(joints);
    s.peer = Some(SplinesPeer::new(&s.source));
    Ok(s)
}

/// `crowd`: 1,000 instances at random phases.
pub fn crowd(bvh: &Path) -> Result<Scenario, tcb_io::Error> {
    let (clip, joints) = cmu(bvh, RotationMode::Hermite)?;
    let end = clip.time_range().map_or(0.0, |r| r.1);
    let mut rng = Rng(0xc20d);
    let mut s = Scenario::new("crowd", clip, frames(1.0, 60.0)[..60].to_vec());
    s.phases = (0..1000).map(|_| rng.range(0.0, end - 1.0)).collect();
    s.joints = Some(joints);
    s.parallel = true;
    Ok(s)
}

fn scalar_track(times: Vec<f64>, rng: &mut Rng) -> NamedTrack {
    let n = times.len();
    let values = (0..n).map(|_| rng.range(-1.0, 1.0) as f32).collect();
    let track = Track::new(
        times,
        values,
        vec![KeyParams::default(); n],
        &TrackSettings::default(),
    )
    .expect("valid synthetic keys");
    NamedTrack {
        name: String::new(),
        data: TrackData::Scalar(track),
    }
}

/// `wide`: 10,000 scalar channels on one grid of 61 keys over 2 s.
pub fn wide() -> Scenario {
    let mut rng = Rng(0x1de);
    let times: Vec<f64> = (0..61).map(|k| k as f64 / 30.0).collect();
    let tracks = (0..10_000)
        .map(|i| NamedTrack {
            name: format!("w{i}"),
            ..scalar_track(times.clone(), &mut rng)
        })
        .collect();
    let clip = tcb_core::SourceClip::new("wide", tracks).expect("unique track names");
    let mut s = Scenario::new("wide", clip, frames(2.0, 60.0));
    s.peer = Some(SplinesPeer::new(&s.source));
    s.read_limit = true;
    s
}

/// `sparse`: 500 scalar tracks, each with 10 to 40 random key times in [0, 2] s.
pub fn sparse() -> Scenario {
    Scenario::new("sparse", sparse_clip(), frames(2.0, 60.0))
}

/// `sparse-seek`: [`sparse`]'s clip at as many random times, so that every
/// frame seeks every lane (scrubbing a timeline of authored curves).
pub fn sparse_seek() -> Scenario {
    let mut rng = Rng(0x5eec5);
    let times = (0..frames(2.0, 60.0).len())
        .map(|_| rng.range(0.0, 2.0))
        .collect();
    Scenario::new("sparse-seek", sparse_clip(), times)
}

fn sparse_clip() -> tcb_core::SourceClip {
    let mut rng = Rng(0x5ba5e);
    let tracks = (0..500)
        .map(|i| {
            let times = own_times(&mut rng);
            NamedTrack {
                name: format!("s{i}"),
                ..scalar_track(times, &mut rng)
            }
        })
        .collect();
    tcb_core::SourceClip::new("sparse", tracks).expect("unique track names")
}

/// 10 to 40 random key times in [0, 2] s, the first at 0 and the last at 2.
fn own_times(rng: &mut Rng) -> Vec<f64> {
    let n = 10 + (rng.next_f64() * 31.0) as usize;
    let mut times: Vec<f64> = (0..n).map(|_| rng.range(0.0, 2.0)).collect();
    times.sort_by(f64::total_cmp);
    times.dedup();
    times[0] = 0.0;
    *times.last_mut().expect("10 or more") = 2.0;
    times
}

/// `sparse-rotations`: 128 rotations, half `hermite` and half `squad`, each
/// on 10 to 40 random key times of its own in [0, 2] s, turning up to 0.5
/// rad between keys (a smooth joint; channels count 4 per rotation).
pub fn sparse_rotations() -> Scenario {
    use glam::{Quat, Vec3};
    let mut rng = Rng(0x5ba5e4);
    let tracks = (0..128)
        .map(|i| {
            let times = own_times(&mut rng);
            let mut q = Quat::IDENTITY;
            let values: Vec<Quat> = times
                .iter()
                .map(|_| {
                    let axis = Vec3::new(
                        rng.range(-1.0, 1.0) as f32,
                        rng.range(-1.0, 1.0) as f32,
                        rng.range(-1.0, 1.0) as f32,
                    )
                    .try_normalize()
                    .unwrap_or(Vec3::Z);
                    q = (q * Quat::from_axis_angle(axis, rng.range(0.0, 0.5) as f32)).normalize();
                    q
                })
                .collect();
            let settings = TrackSettings {
                rotation: if i % 2 == 0 {
                    RotationMode::Hermite
                } else {
                    RotationMode::Squad
                },
                ..TrackSettings::default()
            };
            let n = times.len();
            let track = tcb_core::RotationTrack::new(
                times,
                values,
                vec![KeyParams::default(); n],
                &settings,
            )
            .expect("valid synthetic rotation keys");
            NamedTrack {
                name: format!("r{i}"),
                data: TrackData::Quat(track),
            }
        })
        .collect();
    let clip = tcb_core::SourceClip::new("sparse-rotations", tracks).expect("unique track names");
    Scenario::new("sparse-rotations", clip, frames(2.0, 60.0))
}

/// Every scenario, in report order.
pub fn all(bvh: &Path) -> Result<Vec<Scenario>, tcb_io::Error> {
    named(bvh, |_| true)
}

/// The scenario names, in report order.
pub const NAMES: [&str; 12] = [
    "character-hermite",
    "character-squad",
    "character-quantized",
    "crowd",
    "wide",
    "sparse",
    "sparse-rotations",
    "seek",
    "sparse-seek",
    "character-reduced",
    "character-compressed",
    "character-compressed-acl",
];

/// The scenarios whose name `want` accepts, built only if wanted (the
/// reduced character runs `tcb reduce` first).
pub fn named(bvh: &Path, want: impl Fn(&str) -> bool) -> Result<Vec<Scenario>, tcb_io::Error> {
    // The two compressions (a search each, about 2 s) side by side.
    let mut packed = [None, None];
    if want("character-compressed") && want("character-compressed-acl") {
        let (a, b) = rayon::join(|| compress_cmu(bvh, false), || compress_cmu(bvh, true));
        packed = [Some(a?), Some(b?)];
    }
    let mut out = Vec::new();
    for name in NAMES.into_iter().filter(|n| want(n)) {
        out.push(match name {
            "character-hermite" => character(bvh, RotationMode::Hermite)?,
            "character-squad" => character(bvh, RotationMode::Squad)?,
            "character-quantized" => character_quantized(bvh)?,
            "crowd" => crowd(bvh)?,
            "wide" => wide(),
            "sparse" => sparse(),
            "sparse-rotations" => sparse_rotations(),
            "seek" => seek(bvh)?,
            "sparse-seek" => sparse_seek(),
            "character-compressed" | "character-compressed-acl" => {
                let acl = name.ends_with("acl");
                let packed = match packed[usize::from(acl)].take() {
                    Some(p) => p,
                    None => compress_cmu(bvh, acl)?,
                };
                packed_scenario(name, packed, bvh)?
            }
            _ => character_reduced(bvh)?,
        });
    }
    Ok(out)
}
