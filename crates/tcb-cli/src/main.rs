//! `tcb`: sample Kochanek-Bartels animation clips from the command line.
//!
//! ```text
//! tcb sample CLIP.json --at 0,0.25,1.5
//! tcb sample CLIP.json --fps 60 [--from A] [--to B]
//! tcb sample CLIP.json --inbetweens N [--scalar] [--velocity]
//! tcb import FILE.bvh -o CLIP.json [--rotation squad|hermite]
//! tcb import FILE.gltf|FILE.glb -o CLIP.json [--animation NAME_OR_INDEX]
//! tcb info CLIP
//! tcb bench CLIP [--fps 60] [--instances N] [--threads N]
//! tcb view CLIP [-o PAGE.html] [--fps N] [--joint NAME]
//! ```
//!
//! `sample` also reads BVH and glTF files directly (imported on the fly).
//!
//! CSV goes to stdout; errors go to stderr as one line, with a non-zero exit
//! status and nothing on stdout.

#![forbid(unsafe_code)]

mod view;

use clap::{Args, Parser, Subcommand};
use std::io::{self, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use tcb_core::SourceClip;
use tcb_core::sample_times::{frame_count, frame_times, inbetweens};

/// Most sample times one command will produce.
const MAX_SAMPLES: u64 = 100_000_000;

#[derive(Parser)]
#[command(
    name = "tcb",
    version,
    about = "Kochanek-Bartels (TCB) spline animation tool"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// glTF: let buffer URIs name files outside the .gltf's folder (absolute
    /// paths, '..', symbolic links out of it). Only for a trusted asset tree.
    #[arg(long, global = true)]
    allow_outside_paths: bool,
}

/// `--allow-outside-paths`, read by every command that imports.
static ALLOW_OUTSIDE_PATHS: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// [`tcb_io::load`] with `--allow-outside-paths`.
fn load(path: &std::path::Path) -> Result<tcb_io::Loaded, tcb_io::Error> {
    tcb_io::load_with(path, &import_options_plain())
}

fn import_options_plain() -> tcb_io::ImportOptions {
    tcb_io::ImportOptions::default()
        .allow_outside_paths(ALLOW_OUTSIDE_PATHS.load(std::sync::atomic::Ordering::Relaxed))
}

#[derive(Subcommand)]
enum Command {
    /// Sample a clip and print CSV: a `time` column, then one column per channel.
    Sample(SampleArgs),
    /// Import a BVH or glTF file as a clip (tcb-clip/1 JSON).
    Import(ImportArgs),
    /// Export a clip to glTF 2.0 (.gltf with an embedded buffer, or .glb).
    Export(ExportArgs),
    /// Fit dense animation with far fewer Hermite keys within a stated error.
    Reduce(ReduceArgs),
    /// Quantize and pack a clip within a stated error: a binary .tcbc clip.
    Compress(CompressArgs),
    /// Print a clip's tracks, key grids, runtime layout and bytes.
    Info(InfoArgs),
    /// Time the runtime on a clip: ns per joint and per channel, bytes, flags.
    Bench(BenchArgs),
    /// Draw tracks as an SVG: values, velocity, speed or the 2D path.
    Plot(PlotArgs),
    /// Write the figures of docs/figures/ (the paper's, redrawn) to a directory.
    Figures(FiguresArgs),
    /// Write one self-contained HTML page that plays the clip on its
    /// skeleton (three.js inside), with each joint's curves.
    View(ViewArgs),
}

#[derive(Args)]
struct ViewArgs {
    /// The clip: clip JSON, BVH, glTF, GLB or a packed .tcbc (a clip with
    /// no skeleton shows its curves alone).
    clip: PathBuf,
    /// The page to write (default: the clip's file name with .html, in the
    /// current directory).
    #[arg(short, long, value_name = "OUT.html")]
    output: Option<PathBuf>,
    /// Poses per second the page holds (default: the clip's key times when
    /// they are evenly spaced, as in motion capture; else 60).
    #[arg(long, value_name = "FPS", allow_hyphen_values = true)]
    fps: Option<f64>,
    /// The joint, or group of tracks (`ball` for `ball.position`), whose
    /// curves show first (default: the root joint, or the first group).
    #[arg(long, value_name = "NAME")]
    joint: Option<String>,
    /// BVH: rotation mode of its rotation tracks, as `tcb import`.
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF: the animation, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
}

#[derive(Args)]
struct PlotArgs {
    /// The clip: clip JSON, BVH, glTF, GLB or a packed .tcbc.
    clip: PathBuf,
    /// The SVG to write.
    #[arg(short, long, value_name = "OUT.svg")]
    output: PathBuf,
    /// A track to draw (repeatable; default: of each kind, the first
    /// tracks up to 16 channels). Each kind (vectors, rotations, scalars)
    /// gets a panel; tracks the mode cannot draw are skipped, and named.
    #[arg(long, value_name = "NAME")]
    track: Vec<String>,
    /// Start of the time range, seconds (default: 15% of the keys' span
    /// before the first key; the first key with --path).
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    from: Option<f64>,
    /// End of the time range, seconds.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    to: Option<f64>,
    /// d/dt of each channel.
    #[arg(long, conflicts_with_all = ["speed", "path", "components"])]
    velocity: bool,
    /// The length of the velocity (rotations: angular speed, degrees/s).
    #[arg(long, conflicts_with_all = ["path", "components"])]
    speed: bool,
    /// The 2D path of vector tracks, with keys, tangent handles and
    /// inbetweens (other tracks are skipped).
    #[arg(long)]
    path: bool,
    /// Rotations: the 4 components instead of angle and axis; with --path,
    /// the two components to draw (default x,y; for a rig, its ground
    /// plane: x,z when Y is up).
    #[arg(long, value_name = "x,y", num_args = 0..=1, default_missing_value = "")]
    components: Option<String>,
    /// Inbetween dots per segment at equal time steps (default 8 with --path).
    #[arg(long, value_name = "N")]
    inbetweens: Option<usize>,
    /// BVH: rotation mode of its rotation tracks, as `tcb import`.
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF: the animation, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
}

#[derive(Args)]
struct FiguresArgs {
    /// The directory to write the SVGs to (created if missing).
    #[arg(short, long, value_name = "DIR")]
    output: PathBuf,
    /// The repository holding examples/clips/ (default: the current directory).
    #[arg(long, value_name = "DIR", default_value = ".")]
    root: PathBuf,
}

#[derive(Args)]
struct InfoArgs {
    /// The clip: clip JSON, BVH, glTF, GLB or a packed .tcbc.
    clip: PathBuf,
    /// Compile with 16-bit controls (and print each track's error bound).
    #[arg(long)]
    quantize: bool,
    /// BVH: rotation mode of its rotation tracks, as `tcb import`.
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF: the animation, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
}

#[derive(Args)]
struct BenchArgs {
    /// The clip: clip JSON, BVH, glTF, GLB or a packed .tcbc.
    clip: PathBuf,
    /// Compile with 16-bit controls.
    #[arg(long)]
    quantize: bool,
    /// Frames per second of playback.
    #[arg(
        long,
        value_name = "FPS",
        default_value_t = 60.0,
        allow_hyphen_values = true
    )]
    fps: f64,
    /// Instances at random phases (more than 1 also times them with rayon).
    #[arg(long, value_name = "N", default_value_t = 1)]
    instances: usize,
    /// Rayon threads for the parallel column (default: one per core).
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
    /// Timing rounds (the median is reported).
    #[arg(long, default_value_t = 11)]
    rounds: usize,
    /// Milliseconds per timing.
    #[arg(long, value_name = "MS", default_value_t = 20)]
    slice_ms: u64,
    /// BVH: rotation mode of its rotation tracks, as `tcb import`.
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF: the animation, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
}

#[derive(Args)]
struct ReduceArgs {
    /// The input: clip JSON, BVH, glTF or GLB.
    input: PathBuf,
    /// The clip to write (tcb-clip/1 JSON; written only once it is verified).
    #[arg(short, long, value_name = "OUT.json")]
    output: PathBuf,
    #[command(flatten)]
    error: ErrorArgs,
    /// Which tracks share key times.
    #[arg(long, value_name = "track|joint|clip", default_value = "track")]
    knots: tcb_fit::Knots,
    /// Tangents: derived by the TCB rule from neighbouring keys (values only
    /// stored), explicit in/out tangents on every key, or per track the one
    /// that stores fewer numbers.
    #[arg(long, value_name = "best|derived|explicit", default_value = "best")]
    tangents: tcb_fit::Tangents,
    /// BVH input: rotation mode of its rotation tracks, as `tcb import`
    /// (the reference is the input played that way).
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF input: the animation to reduce, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
    /// When fitted tracks go back on the input's shared key grid, at the
    /// cost of bytes, where the reduced clip would play slower than the
    /// input (by the estimate of instructions per frame printed on stderr):
    /// `balanced` when the fits add a larger share per frame than they save
    /// of the input's bytes, `never-slower` always, `fewest-bytes` never
    #[arg(
        long,
        value_name = "balanced|never-slower|fewest-bytes",
        default_value = "balanced"
    )]
    speed: tcb_fit::Speed,
    /// `--speed never-slower` (kept for scripts that use it).
    #[arg(long, hide = true, conflicts_with = "speed")]
    never_slower: bool,
    /// Milliseconds for the quick timing of input and output that follows
    /// the reduction (ns per joint per frame, both from one run; 0: none).
    #[arg(long, value_name = "MS", default_value_t = 300)]
    timing_ms: u64,
}

/// The error a result is held to (`reduce` and `compress`, docs/reduce.md).
#[derive(Args)]
struct ErrorArgs {
    /// Largest error allowed, in the clip's units (shell: model-space
    /// distance, default 6e-5 x the rest-pose height; value: per component,
    /// default 1e-4).
    #[arg(long, value_name = "E", allow_hyphen_values = true)]
    tolerance: Option<f64>,
    /// Shell radius: distance of the virtual points from each joint, in the
    /// clip's units (default 0.018 x height).
    #[arg(long, value_name = "R", allow_hyphen_values = true)]
    shell: Option<f64>,
    /// Error metric (default: shell when the input has a skeleton, else value).
    #[arg(long, value_name = "shell|value")]
    metric: Option<tcb_fit::Metric>,
    /// Value metric: largest rotation error in degrees (default 0.01).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    rotation_tolerance: Option<f64>,
}

#[derive(Args)]
struct CompressArgs {
    /// The input: clip JSON, BVH, glTF or GLB, every track on one even grid
    /// of key times (motion capture, baked animation).
    input: PathBuf,
    /// The packed clip to write (written only once its error is measured
    /// within the tolerance).
    #[arg(short, long, value_name = "OUT.tcbc")]
    output: PathBuf,
    #[command(flatten)]
    error: ErrorArgs,
    /// Keys between seek points: a seek decodes up to N - 1 keys (smaller
    /// seeks faster and takes more bytes); a multiple of 32 up to 1024.
    #[arg(long, value_name = "N", default_value_t = 64)]
    seek_keys: usize,
    /// BVH input: how the reference plays its rotations (default hermite,
    /// as the packed clip plays them; with squad, the difference between
    /// the two counts in the measured error).
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF input: the animation, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
}

#[derive(Args)]
struct ExportArgs {
    /// The clip (tcb-clip/1 JSON, or anything `sample` reads).
    clip: PathBuf,
    /// The file to write: .glb or .gltf.
    #[arg(short, long, value_name = "OUT.glb|OUT.gltf")]
    output: PathBuf,
    /// Largest error allowed where the curve must be resampled (relative to max(1, |value|)).
    #[arg(long, value_name = "E", default_value_t = 1e-5)]
    max_error: f64,
    /// Export track FROM under the name TO (glTF animates only
    /// `<node>.translation`, `.rotation`, `.scale` and `.weights.<i>`); repeatable.
    #[arg(long, value_name = "FROM=TO")]
    rename: Vec<String>,
}

#[derive(Args)]
struct ImportArgs {
    /// The file to import (.bvh, .gltf, .glb).
    file: PathBuf,
    /// The clip to write (replaced only once it is complete).
    #[arg(short, long, value_name = "CLIP.json")]
    output: PathBuf,
    /// BVH: rotation mode of the rotation tracks.
    #[arg(long, value_name = "squad|hermite")]
    rotation: Option<tcb_core::RotationMode>,
    /// glTF: the animation to import, by name or index (default: the first).
    #[arg(long, value_name = "NAME_OR_INDEX")]
    animation: Option<String>,
}

#[derive(Args)]
#[command(group = clap::ArgGroup::new("times").required(true).args(["at", "fps", "inbetweens"]))]
struct SampleArgs {
    /// The clip file (tcb-clip/1 JSON; .bvh, .gltf and .glb are imported first; a .tcbc plays its packed stream).
    clip: PathBuf,
    /// Sample at these times (seconds, comma separated; may be negative or huge).
    #[arg(long, value_name = "T,T,...", allow_hyphen_values = true)]
    at: Option<String>,
    /// Sample every 1/FPS seconds.
    #[arg(long, value_name = "FPS", allow_hyphen_values = true)]
    fps: Option<f64>,
    /// With --fps: first time (default: the clip's first key).
    #[arg(long, value_name = "A", allow_hyphen_values = true)]
    from: Option<f64>,
    /// With --fps: last time, included when on the grid (default: the clip's last key).
    #[arg(long, value_name = "B", allow_hyphen_values = true)]
    to: Option<f64>,
    /// Every key time of the clip and N evenly spaced times inside each interval.
    #[arg(long, value_name = "N")]
    inbetweens: Option<u32>,
    /// Use the scalar reference implementation (tcb-core) instead of the SIMD runtime.
    #[arg(long)]
    scalar: bool,
    /// Add d/dt columns named `<column>.d` after the value columns.
    #[arg(long)]
    velocity: bool,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    ALLOW_OUTSIDE_PATHS.store(
        cli.allow_outside_paths,
        std::sync::atomic::Ordering::Relaxed,
    );
    let result = match cli.command {
        Command::Sample(args) => sample(&args),
        Command::Import(args) => import(&args),
        Command::Export(args) => export(&args),
        Command::Reduce(args) => reduce(&args),
        Command::Compress(args) => compress(&args),
        Command::Info(args) => info(&args),
        Command::Bench(args) => bench(&args),
        Command::Plot(args) => plot(&args),
        Command::Figures(args) => figures(&args),
        Command::View(args) => view_page(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e)
            if e.downcast_ref::<io::Error>()
                .is_some_and(|e| e.kind() == io::ErrorKind::BrokenPipe) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("tcb: error: {}", one_line(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}

/// `message` with its control characters escaped (`\n`, `\u{1b}`): names
/// come from files, and may hold line breaks or terminal escapes that
/// would otherwise break the one-line message or reach the terminal.
fn one_line(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    for c in message.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

type BoxError = Box<dyn std::error::Error>;

fn warn(warnings: &[String]) {
    for w in warnings {
        eprintln!("tcb: warning: {}", one_line(w));
    }
}

/// A file's extension, lower case (empty without one).
fn extension(path: &std::path::Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Refuses, before anything is read, a clip path that the commands which
/// also play packed clips cannot read: a directory, or a name of no type
/// they know (the message lists `.tcbc` with `tcb_io`'s types).
fn playable(path: &std::path::Path) -> Result<(), BoxError> {
    if path.is_dir() {
        return Err(format!("{}: a directory, not a clip file", path.display()).into());
    }
    let what = match extension(path).as_str() {
        "json" | "bvh" | "gltf" | "glb" | "tcbc" => return Ok(()),
        "" => "no file extension to tell its type".to_string(),
        ext => format!("unknown file type '.{ext}'"),
    };
    Err(format!(
        "{}: {what} (expected .json, .bvh, .gltf, .glb or .tcbc)",
        path.display()
    )
    .into())
}

/// `path` loaded (BVH, glTF or clip JSON) with the import options of
/// `rotation` and `animation`, its warnings printed.
fn load_input(
    path: &std::path::Path,
    rotation: Option<tcb_core::RotationMode>,
    animation: Option<&String>,
) -> Result<tcb_io::Loaded, BoxError> {
    let loaded = tcb_io::load_with(path, &import_options(path, rotation, animation)?)?;
    warn(&loaded.warnings);
    Ok(loaded)
}

/// Import options for `file`, refusing the ones its format does not take.
fn import_options(
    file: &std::path::Path,
    rotation: Option<tcb_core::RotationMode>,
    animation: Option<&String>,
) -> Result<tcb_io::ImportOptions, BoxError> {
    match extension(file).as_str() {
        "bvh" if animation.is_some() => return Err("--animation is for glTF files".into()),
        "gltf" | "glb" if rotation.is_some() => {
            return Err(
                "--rotation is for BVH files (glTF rotations keep their own interpolation)".into(),
            );
        }
        "json" if rotation.is_some() || animation.is_some() => {
            return Err(
                "--rotation and --animation are for BVH and glTF files (a clip keeps its own modes)"
                    .into(),
            );
        }
        _ => {}
    }
    Ok(import_options_plain()
        .rotation(rotation.unwrap_or_default())
        .animation(animation.cloned()))
}

fn import(args: &ImportArgs) -> Result<(), BoxError> {
    if !matches!(extension(&args.file).as_str(), "bvh" | "gltf" | "glb") {
        return Err(format!(
            "{}: can import .bvh, .gltf and .glb files",
            args.file.display()
        )
        .into());
    }
    if extension(&args.output) != "json" {
        return Err(format!("{}: the output must end in .json", args.output.display()).into());
    }
    let loaded = load_input(&args.file, args.rotation, args.animation.as_ref())?;
    tcb_io::write_clip_doc(&loaded.doc, &args.output)?;
    let keys: usize = loaded.doc.tracks.iter().map(|t| t.times.len()).sum();
    let (a, b) = loaded.clip.time_range().unwrap_or((0.0, 0.0));
    eprintln!(
        "tcb: wrote {}: {} tracks, {keys} keys, {a} to {b} s",
        args.output.display(),
        loaded.doc.tracks.len()
    );
    Ok(())
}

fn export(args: &ExportArgs) -> Result<(), BoxError> {
    playable(&args.clip)?;
    if !(args.max_error > 0.0 && args.max_error.is_finite()) {
        return Err(format!(
            "--max-error must be a positive number, got {}",
            args.max_error
        )
        .into());
    }
    let ext = extension(&args.output);
    if ext != "glb" && ext != "gltf" {
        return Err(format!(
            "{}: the output must end in .glb or .gltf",
            args.output.display()
        )
        .into());
    }
    let rename = renames(&args.rename)?;
    let (clip, skeleton) = load_any(&args.clip, &import_options_plain())?;
    let options = tcb_io::gltf_export::ExportOptions::default()
        .max_error(args.max_error)
        .rename(rename);
    let report =
        tcb_io::gltf_export::export_file(&clip, skeleton.as_ref(), &args.output, &options)?;
    warn(&report.notes);
    eprintln!(
        "tcb: wrote {}: {}",
        args.output.display(),
        export_summary(&report, skeleton.as_ref())
    );
    // The error as read back, unless a note above already named it (the
    // resampling's or the f32 key times' note, for the worst track when
    // it is resampled or its times moved): the same number twice read as
    // two problems.
    let noted = !report.notes.is_empty()
        && report.tracks.iter().any(|t| {
            (t.resampled_error.is_some() || t.time_rounding.is_some())
                && t.error() == Some(report.max_error())
        });
    if report.max_error() > args.max_error && !noted {
        eprintln!(
            "tcb: warning: max error {:.4e} is above --max-error {:e}, as `tcb import` reads the export back",
            report.max_error(),
            args.max_error
        );
    }
    Ok(())
}

/// `--rename FROM=TO` arguments as pairs.
fn renames(rename: &[String]) -> Result<Vec<(String, String)>, String> {
    rename
        .iter()
        .map(|r| {
            r.split_once('=')
                .filter(|(a, b)| !a.is_empty() && !b.is_empty())
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .ok_or_else(|| format!("--rename {r}: expected FROM=TO"))
        })
        .collect()
}

/// `tcb export`'s account of what it wrote: tracks exact, resampled or on
/// key times that glTF's f32 moves, the largest error and where, and the
/// skeleton.
fn export_summary(
    report: &tcb_io::gltf_export::ExportReport,
    skeleton: Option<&tcb_core::skeleton::Skeleton>,
) -> String {
    // Not exact: resampled, or on key times that glTF's f32 moves.
    let inexact: Vec<_> = report
        .tracks
        .iter()
        .filter_map(|t| t.error().map(|e| (&t.name, e)))
        .collect();
    let resampled = report
        .tracks
        .iter()
        .filter(|t| t.resampled_error.is_some())
        .count();
    let shifts: Vec<f64> = report
        .tracks
        .iter()
        .filter_map(|t| t.time_rounding.map(|r| r.largest_shift))
        .collect();
    let moved = match shifts.iter().copied().reduce(f64::max) {
        Some(s) => format!(
            ", {} on keys moved by glTF's f32 times (up to {s:.4e} s)",
            shifts.len()
        ),
        None => String::new(),
    };
    let worst = inexact
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(String::new(), |(n, e)| {
            format!(" (max error {e:.4e}, in {n})")
        });
    let joints = skeleton.map_or("no skeleton".to_string(), |s| {
        format!("{} joints as the node hierarchy", s.joints().len())
    });
    format!(
        "{} tracks, {} exact, {resampled} resampled{moved}{worst}; {joints}",
        report.tracks.len(),
        report.tracks.len() - inexact.len(),
    )
}

fn compress(args: &CompressArgs) -> Result<(), BoxError> {
    if extension(&args.output) != "tcbc" {
        return Err(format!("{}: the output must end in .tcbc", args.output.display()).into());
    }
    if extension(&args.input) == "tcbc" {
        return Err(format!(
            "{}: already packed; compress its source (BVH, glTF or clip JSON)",
            args.input.display()
        )
        .into());
    }
    output_folder_exists(&args.output)?;
    let started = std::time::Instant::now();
    // A BVH's rotations are samples: played as `hermite`, the way a packed
    // clip plays them, unless asked otherwise.
    let rotation = args
        .rotation
        .or((extension(&args.input) == "bvh").then_some(tcb_core::RotationMode::Hermite));
    let loaded = load_input(&args.input, rotation, args.animation.as_ref())?;
    // The grid's rotations play `hermite` in a packed clip: say so where
    // the input's do not (the error is measured against the input).
    let tracks = loaded.clip.tracks();
    let most = tracks.iter().map(|t| t.data.times().len()).max();
    let replayed = tracks
        .iter()
        .filter(|t| Some(t.data.times().len()) == most)
        .filter(|t| matches!(&t.data, tcb_core::TrackData::Quat(r) if r.settings().rotation != tcb_core::RotationMode::Hermite))
        .count();
    if replayed > 0 {
        eprintln!(
            "tcb: {replayed} rotation(s) on the clip's grid are squad or slerp: a packed clip plays them as hermite, measured against the input as it plays them (for a clip from tcb reduce of a BVH, reduce with --rotation hermite)"
        );
    }
    let options = tcb_fit::CompressOptions::default()
        .tolerance(args.error.tolerance)
        .shell(args.error.shell)
        .metric(args.error.metric)
        .rotation_tolerance(args.error.rotation_tolerance)
        .seek_keys(Some(args.seek_keys));
    let c = with_progress("tcb: measuring {bar:30} {pos}/{len} clips", |progress| {
        tcb_fit::compress(&loaded.clip, loaded.skeleton.as_ref(), &options, progress)
    })?;
    eprintln!("tcb: {}", metric_line(&c.settings));
    let bytes = c.packed.to_bytes();
    tcb_io::write_atomically(&args.output, &bytes)?;
    eprintln!(
        "tcb: wrote {} in {:.1} s ({} clips measured)",
        args.output.display(),
        started.elapsed().as_secs_f64(),
        c.evaluations
    );
    println!("{}", c.summary_line());
    Ok(())
}

/// The output's folder exists: found out before the work, not after it.
fn output_folder_exists(output: &std::path::Path) -> Result<(), BoxError> {
    match output.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) if dir.exists() && !dir.is_dir() => {
            Err(format!("{}: not a directory", dir.display()).into())
        }
        Some(dir) if !dir.is_dir() => Err(format!("{}: no such directory", dir.display()).into()),
        _ => Ok(()),
    }
}

/// The metric and its tolerances, as `tcb reduce` and `tcb compress` print
/// them.
fn metric_line(s: &tcb_fit::reduce::Settings) -> String {
    match s.metric {
        tcb_fit::Metric::Shell => format!(
            "metric shell, tolerance {:e}, shell {:e} (rest-pose height {})",
            s.tolerance, s.shell, s.height
        ),
        tcb_fit::Metric::Value => format!(
            "metric value, tolerance {:e}, rotation tolerance {} degrees",
            s.tolerance, s.rotation_tolerance
        ),
    }
}

/// On stderr: the settings `tcb reduce` worked with, each round's fits and
/// error, and the tracks kept as they were.
fn report_rounds(reduced: &tcb_fit::Reduced) {
    let s = &reduced.settings;
    eprintln!(
        "tcb: {}, knots {}, tangents {}",
        metric_line(s),
        s.knots.name(),
        s.tangents.name()
    );
    for a in &reduced.attempts {
        eprintln!(
            "tcb: round {}: {} groups fitted, values {}, error {:.3} of the tolerance ({} at {} s)",
            a.round + 1,
            a.fitted,
            a.values,
            a.ratio,
            a.worst.at,
            a.worst.time
        );
    }
    if !reduced.kept.is_empty() {
        eprintln!(
            "tcb: {} tracks kept as they were: {}",
            reduced.kept.len(),
            reduced.kept.join(", ")
        );
    }
}

/// `work` with a progress bar on stderr (drawn only on a terminal) that it
/// moves by calling its argument with (done, of how many).
fn with_progress<T>(template: &str, work: impl FnOnce(&(dyn Fn(usize, usize) + Sync)) -> T) -> T {
    let bar = indicatif::ProgressBar::new(0).with_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let progress = |done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let result = work(&progress);
    bar.finish_and_clear();
    result
}

/// Any clip file as a source clip and its skeleton: a `.tcbc` as its
/// reference (the dequantized keys) and the skeleton it keeps, the rest
/// through `tcb_io` (warnings printed).
fn load_any(
    path: &std::path::Path,
    options: &tcb_io::ImportOptions,
) -> Result<(tcb_core::SourceClip, Option<tcb_core::skeleton::Skeleton>), BoxError> {
    if extension(path) == "tcbc" {
        let (clip, runtime) = load_tcbc(path)?;
        let skeleton = runtime.packed().and_then(|p| p.skeleton.clone());
        return Ok((clip, skeleton));
    }
    let loaded = tcb_io::load_with(path, options)?;
    warn(&loaded.warnings);
    Ok((loaded.clip, loaded.skeleton))
}

/// A `.tcbc` file: its reference clip (the dequantized keys, for
/// `--scalar` and the track list) and its runtime clip.
fn load_tcbc(
    path: &std::path::Path,
) -> Result<(tcb_core::SourceClip, std::sync::Arc<tcb_runtime::Clip>), BoxError> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let in_file = |e: tcb_runtime::PackError| format!("{}: {e}", path.display());
    let packed = std::sync::Arc::new(tcb_runtime::Packed::from_bytes(&bytes).map_err(in_file)?);
    let reference = packed.decode().and_then(|s| s.to_clip()).map_err(in_file)?;
    let runtime = tcb_runtime::Clip::from_packed(packed).map_err(in_file)?;
    Ok((reference, std::sync::Arc::new(runtime)))
}

fn reduce(args: &ReduceArgs) -> Result<(), BoxError> {
    if extension(&args.output) != "json" {
        return Err(format!("{}: the output must end in .json", args.output.display()).into());
    }
    output_folder_exists(&args.output)?;
    let started = std::time::Instant::now();
    let loaded = load_input(&args.input, args.rotation, args.animation.as_ref())?;
    let options = tcb_fit::ReduceOptions::default()
        .tolerance(args.error.tolerance)
        .shell(args.error.shell)
        .metric(args.error.metric)
        .rotation_tolerance(args.error.rotation_tolerance)
        .knots(args.knots)
        .tangents(args.tangents)
        .speed(if args.never_slower {
            tcb_fit::Speed::NeverSlower
        } else {
            args.speed
        });
    let input = tcb_fit::reduce::Input {
        doc: &loaded.doc,
        clip: &loaded.clip,
        skeleton: loaded.skeleton.as_ref(),
    };
    let reduced = with_progress("tcb: fitting {bar:30} {pos}/{len} groups", |progress| {
        tcb_fit::reduce(input, &options, progress)
    })?;
    report_rounds(&reduced);
    tcb_io::write_clip_doc(&reduced.doc, &args.output)?;
    eprintln!(
        "tcb: wrote {} in {:.2} s",
        args.output.display(),
        started.elapsed().as_secs_f64()
    );
    if reduced.after.bytes > reduced.before.bytes {
        eprintln!(
            "tcb: note: the reduced clip compiles to more bytes than the input ({} against {}): \
             tracks on key times of their own play as loose lanes, which hold more per key \
             than a key grid the tracks share (--knots clip keeps one grid)",
            reduced.after.bytes, reduced.before.bytes
        );
    }
    report_speed(&loaded.clip, &reduced, args.timing_ms);
    println!("{}", reduced.summary_line());
    Ok(())
}

/// On stderr: the input's and output's estimated runtime instructions per
/// frame (`tcb_fit::cost`), and, unless `ms` is 0, their ns per animated
/// joint per frame at 60 fps timed in one run (alternating rounds, medians
/// ± MAD, about `ms` milliseconds in all: a quick timing).
fn report_speed(input: &tcb_core::SourceClip, reduced: &tcb_fit::Reduced, ms: u64) {
    let (c0, c1) = (reduced.before_cost, reduced.after_cost);
    eprintln!(
        "tcb: estimated runtime cost: input {c0:.0}, output {c1:.0} instructions per frame ({:.2}x){}",
        c1 / c0,
        if c1 > c0 {
            ": slower; tracks on key times of their own play as loose lanes, which cost more per frame than a shared grid's (--speed never-slower trades bytes for it; docs/benchmarks.md)"
        } else {
            ""
        }
    );
    if let Some((smaller, cost)) = &reduced.declined {
        eprintln!(
            "tcb: fits put back on the input's key grid to play no slower than the input: \
             the fewest bytes found ({} keys, {} bytes) would cost {cost:.0} instructions per frame \
             (with --speed fewest-bytes: kept)",
            smaller.keys, smaller.bytes
        );
    }
    if ms == 0 {
        return;
    }
    let [(t0, s0), (t1, s1)] =
        quick_timing(input, &reduced.clip, std::time::Duration::from_millis(ms));
    let joints = animated_joints(input);
    let per_joint = |s: f64| s * 1e9 / joints.max(1) as f64;
    eprintln!(
        "tcb: a quick timing ({ms} ms, one run{}): input {:.2} ± {:.2}, output {:.2} ± {:.2} ns per joint per frame ({:.2}x), {joints} animated joints at 60 fps",
        if cfg!(debug_assertions) {
            ", a debug build"
        } else {
            ""
        },
        per_joint(t0),
        per_joint(s0),
        per_joint(t1),
        per_joint(s1),
        t1 / t0
    );
}

/// Seconds per frame of `a` and `b` compiled, played forward at 60 fps over
/// `a`'s keys: medians of rounds timed alternately, in about `budget`, and
/// the rounds' MAD (median absolute deviation).
fn quick_timing(a: &SourceClip, b: &SourceClip, budget: std::time::Duration) -> [(f64, f64); 2] {
    use std::sync::Arc;
    let (start, end) = a.time_range().unwrap_or((0.0, 0.0));
    let frames: Vec<f64> = (0..=((end - start) * 60.0).floor() as usize)
        .map(|i| start + i as f64 / 60.0)
        .collect();
    let pass = |clip: &SourceClip| {
        let mut instance = tcb_runtime::Instance::new(Arc::new(tcb_runtime::Clip::compile(clip)));
        let frames = &frames;
        Box::new(move || {
            for &t in frames {
                std::hint::black_box(instance.sample(t));
            }
        }) as Box<dyn FnMut() + '_>
    };
    let mut subjects = [
        tcb_bench::measure::Subject {
            name: "input",
            samples: frames.len() as f64,
            run: pass(a),
        },
        tcb_bench::measure::Subject {
            name: "output",
            samples: frames.len() as f64,
            run: pass(b),
        },
    ];
    // Each subject is calibrated for a quarter slice, then timed once a round.
    const ROUNDS: usize = 11;
    let slice = budget.div_f64(2.0 * (ROUNDS as f64 + 0.25));
    let rounds = tcb_bench::measure::rounds_seconds(&mut subjects, ROUNDS, slice);
    let n = frames.len() as f64;
    let per_frame = |i: usize| {
        (
            tcb_bench::noise::median(&rounds[i]) / n,
            tcb_bench::noise::mad(&rounds[i]) / n,
        )
    };
    [per_frame(0), per_frame(1)]
}

/// The distinct `<joint>` of a clip's `<joint>.<part>` track names.
fn animated_joints(clip: &SourceClip) -> usize {
    let mut names: Vec<&str> = clip
        .tracks()
        .iter()
        .map(|t| t.name.rsplit_once('.').map_or(t.name.as_str(), |p| p.0))
        .collect();
    names.sort_unstable();
    names.dedup();
    names.len()
}

/// Bytes as MB with three decimals.
fn mb(bytes: usize) -> String {
    format!("{:.3} MB", bytes as f64 / 1e6)
}

fn info(args: &InfoArgs) -> Result<(), BoxError> {
    playable(&args.clip)?;
    if extension(&args.clip) == "tcbc" {
        return info_tcbc(args);
    }
    let loaded = load_input(&args.clip, args.rotation, args.animation.as_ref())?;
    let clip = &loaded.clip;
    let options = tcb_runtime::CompileOptions::default().quantize(args.quantize);
    let runtime = tcb_runtime::Clip::compile_with(clip, &options);
    let stats = runtime.stats();
    let keys: usize = clip.tracks().iter().map(|t| t.data.times().len()).sum();
    let mut out = String::new();
    use std::fmt::Write as _;
    writeln!(out, "file: {}", args.clip.display())?;
    let range = clip
        .time_range()
        .map_or("no keys".to_string(), |(a, b)| format!("{a} to {b} s"));
    writeln!(
        out,
        "clip: {:?}, {} tracks, {} channels, {keys} keys, {range}",
        clip.name(),
        clip.tracks().len(),
        clip.channel_count()
    )?;
    match &loaded.skeleton {
        Some(s) => {
            let roots = s.joints().iter().filter(|j| j.parent.is_none()).count();
            writeln!(
                out,
                "skeleton: {} joints, {roots} root(s)",
                s.joints().len()
            )?
        }
        None => writeln!(out, "skeleton: none")?,
    }
    write_tracks(&mut out, clip, &runtime, args.quantize)?;
    write_runtime_stats(&mut out, &stats)?;
    writeln!(
        out,
        "bytes: {} compiled (no copy of the source kept), {} read per frame inside the keys",
        mb(stats.bytes),
        stats.bytes_per_frame
    )?;
    io::stdout().lock().write_all(out.as_bytes())?;
    Ok(())
}

/// `tcb info` of a `.tcbc` file: what is stored and how it was made.
fn info_tcbc(args: &InfoArgs) -> Result<(), BoxError> {
    let file = std::fs::metadata(&args.clip)
        .map_err(|e| format!("{}: {e}", args.clip.display()))?
        .len();
    let (clip, runtime) = load_tcbc(&args.clip)?;
    let packed = runtime.packed().expect("compiled from a packed clip");
    let head = packed.head();
    let values = head.stored_values();
    let mut out = String::new();
    use std::fmt::Write as _;
    writeln!(
        out,
        "file: {} ({file} bytes, .tcbc version {})",
        args.clip.display(),
        tcb_runtime::pack::VERSION
    )?;
    writeln!(
        out,
        "clip: {:?}, {} tracks ({} on key times of their own), {} channels, grid of {} keys, {} to {} s ({} s apart)",
        head.name,
        head.tracks.len() + head.loose.len(),
        head.loose.len(),
        clip.channel_count(),
        head.keys,
        head.start,
        head.start + (head.keys - 1) as f64 * head.interval,
        head.interval
    )?;
    writeln!(
        out,
        "made by: {}",
        if packed.note.is_empty() {
            "-"
        } else {
            &packed.note
        }
    )?;
    match &packed.skeleton {
        Some(s) => writeln!(out, "skeleton: {} joints", s.joints().len())?,
        None => writeln!(out, "skeleton: none")?,
    }
    write_packed_tracks(&mut out, head)?;
    let blocks = head.keys.div_ceil(packed.block_keys());
    let factors: Vec<f32> = (0..blocks)
        .map(|b| head.scales.factor(b * packed.block_keys()))
        .collect();
    let (least, most) = factors
        .iter()
        .fold((f32::INFINITY, 0.0f32), |(a, b), &f| (a.min(f), b.max(f)));
    writeln!(
        out,
        "blocks: {blocks} ({} keys each), the grid's steps times {least} to {most} in them (mean {:.4})",
        packed.block_keys(),
        factors.iter().map(|&f| f64::from(f)).sum::<f64>() / blocks as f64
    )?;
    writeln!(
        out,
        "stored: {values} values, {} of them in {} bits of stream ({:.2} bits per value; {:.2} for the whole file)",
        head.keys * head.lanes(),
        packed.stream_bits(),
        packed.stream_bits() as f64 / (head.keys * head.lanes()).max(1) as f64,
        8.0 * file as f64 / values.max(1) as f64
    )?;
    writeln!(
        out,
        "bytes: {} compiled ({} of them the packed stream and its tables)",
        mb(runtime.memory_bytes()),
        packed.stream_bytes()
    )?;
    write_load(&mut out, &args.clip, &runtime)?;
    io::stdout().lock().write_all(out.as_bytes())?;
    Ok(())
}

/// `tcb info`'s table of tracks: kind, keys, time range, rotation mode,
/// pre/post and, with `quantize`, each track's quantization error.
fn write_tracks(
    out: &mut String,
    clip: &SourceClip,
    runtime: &tcb_runtime::Clip,
    quantize: bool,
) -> Result<(), BoxError> {
    use std::fmt::Write as _;
    writeln!(out, "tracks:")?;
    writeln!(
        out,
        "  {:<32} {:<6} {:>6} {:>12} {:>12}  rotation pre/post",
        "name", "kind", "keys", "first", "last"
    )?;
    for (t, id) in clip.tracks().iter().zip(runtime.layout().ids()) {
        let times = t.data.times();
        let (mode, settings) = match &t.data {
            tcb_core::TrackData::Quat(r) => (r.settings().rotation.name(), r.settings()),
            tcb_core::TrackData::Scalar(v) => ("-", v.settings()),
            tcb_core::TrackData::Vec2(v) => ("-", v.settings()),
            tcb_core::TrackData::Vec3(v) => ("-", v.settings()),
            tcb_core::TrackData::Vec4(v) => ("-", v.settings()),
        };
        writeln!(
            out,
            "  {:<32} {:<6} {:>6} {:>12} {:>12}  {mode} {}/{}",
            t.name,
            t.data.kind().name(),
            times.len(),
            times[0],
            times[times.len() - 1],
            settings.pre.name(),
            settings.post.name()
        )?;
        if quantize && runtime.is_quantized(id) == Some(false) {
            writeln!(
                out,
                "    kept in f32: its keys span more than 16 bits can within a finite error"
            )?;
        } else if quantize {
            let e = runtime.quantization_error(id).unwrap_or(0.0);
            writeln!(out, "    quantization error at most {e:e}")?;
        }
    }
    Ok(())
}

/// `tcb info`'s account of the compiled clip: key grids, loose lanes,
/// exact segments and bytes.
fn write_runtime_stats(out: &mut String, stats: &tcb_runtime::ClipStats) -> Result<(), BoxError> {
    use std::fmt::Write as _;
    writeln!(
        out,
        "runtime: {} shared key grid(s), {} loose vector track(s), {} loose rotation(s), {} rotation segment(s) evaluated exactly (f64 squad; {} of them only when velocities are sampled)",
        stats.grids.len(),
        stats.loose_vector_tracks,
        stats.loose_rotation_tracks,
        stats.exact_segments,
        stats.exact_for_velocity_only
    )?;
    for (i, g) in stats.grids.iter().enumerate() {
        writeln!(
            out,
            "  grid {i}: {} keys ({} with incoming tangents stored apart), {} vector channels, {} rotations",
            g.keys, g.keys_with_own_incoming, g.vector_channels, g.rotations
        )?;
    }
    Ok(())
}

/// `tcb info`'s table of a `.tcbc` file's tracks: kind, stored components
/// and quantization step.
fn write_packed_tracks(out: &mut String, head: &tcb_runtime::PackSource) -> Result<(), BoxError> {
    use std::fmt::Write as _;
    writeln!(out, "tracks:")?;
    writeln!(
        out,
        "  {:<32} {:<6} {:>7} {:>14}  relative to / keys of its own",
        "name", "kind", "stored", "step"
    )?;
    let mut loose = head.loose.iter().peekable();
    for (i, t) in head.tracks.iter().enumerate() {
        while let Some(l) = loose.next_if(|l| l.at < head.place(i)) {
            write_loose_track(out, l)?;
        }
        let center = t.center.map_or(String::new(), |c| {
            format!("  [{:.4}, {:.4}, {:.4}, {:.4}]", c[0], c[1], c[2], c[3])
        });
        writeln!(
            out,
            "  {:<32} {:<6} {:>7} {:>14e}{center}",
            t.name,
            t.kind.name(),
            t.stored(),
            t.step
        )?;
    }
    for l in loose {
        write_loose_track(out, l)?;
    }
    Ok(())
}

/// A line of [`write_packed_tracks`] for a track on key times of its own.
fn write_loose_track(out: &mut String, t: &tcb_runtime::pack::LooseTrack) -> Result<(), BoxError> {
    use std::fmt::Write as _;
    let tangents = if t.tangents.is_some() {
        ", explicit tangents"
    } else {
        ""
    };
    writeln!(
        out,
        "  {:<32} {:<6} {:>7} {:>14e}  {} keys{tangents}",
        t.name,
        t.kind.name(),
        t.kind.dim(),
        t.step,
        t.times.len()
    )?;
    Ok(())
}

/// What a game pays to load the `.tcbc` file at `path`: `Clip::from_bytes`
/// (the file's checks, the end blocks decoded, a reference of the end keys
/// compiled), fastest of 3; then the check of every key of `runtime`
/// against the reference.
fn write_load(
    out: &mut String,
    path: &std::path::Path,
    runtime: &tcb_runtime::Clip,
) -> Result<(), BoxError> {
    use std::fmt::Write as _;
    let bytes = std::fs::read(path)?;
    let load = (0..3)
        .map(|_| {
            let t = std::time::Instant::now();
            let clip = tcb_runtime::Clip::from_bytes(&bytes);
            (t.elapsed(), clip.is_ok())
        })
        .min()
        .expect("3 loads");
    writeln!(
        out,
        "load: Clip::from_bytes in {:.2} ms (fastest of 3)",
        load.0.as_secs_f64() * 1e3
    )?;
    let t = std::time::Instant::now();
    runtime
        .verify_packed()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    writeln!(
        out,
        "verified: every key's controls are the reference's, bit for bit ({:.1} ms)",
        t.elapsed().as_secs_f64() * 1e3
    )?;
    Ok(())
}

fn bench(args: &BenchArgs) -> Result<(), BoxError> {
    playable(&args.clip)?;
    if !(args.fps.is_finite() && args.fps > 0.0 && args.fps <= 100_000.0) {
        return Err(format!("--fps {}: must be in (0, 100000]", args.fps).into());
    }
    if args.instances == 0 || args.instances > 1_000_000 {
        return Err("--instances must be 1 to 1000000".into());
    }
    if args.rounds == 0 || args.threads == Some(0) {
        return Err("--rounds and --threads must be at least 1".into());
    }
    let options = tcb_bench::scenarios::FileOptions {
        fps: args.fps,
        instances: args.instances,
        import: import_options(&args.clip, args.rotation, args.animation.as_ref())?,
        compile: tcb_runtime::CompileOptions::default().quantize(args.quantize),
    };
    let scenario = tcb_bench::scenarios::file_with(&args.clip, &options)?;
    if scenario.source.tracks().is_empty() {
        return Err(format!("{}: the clip has no tracks to time", args.clip.display()).into());
    }
    if cfg!(debug_assertions) {
        eprintln!("tcb: warning: a debug build; numbers mean little (build with --release)");
    }
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = args.threads {
        builder = builder.num_threads(n);
    }
    let pool = builder.build()?;
    let slice = std::time::Duration::from_millis(args.slice_ms.max(1));
    eprintln!(
        "tcb: timing {} ({} instance(s), {} frames a pass at {} fps, {} rounds)...",
        args.clip.display(),
        args.instances,
        scenario.times.len(),
        args.fps,
        args.rounds
    );
    let timing = tcb_bench::report::Timing {
        rounds: args.rounds,
        slice,
        reference_samples: None,
    };
    let row = pool.install(|| tcb_bench::report::measure(&scenario, &timing));
    let here = tcb_bench::report::Fingerprint::here();
    let mut out =
        pool.install(|| tcb_bench::report::table(std::slice::from_ref(&row), &here, &timing));
    use std::fmt::Write as _;
    let joints = scenario.joints.unwrap_or(0);
    let rt = row.ns_of("runtime").unwrap_or(f64::NAN);
    let frame = rt * row.channels as f64;
    writeln!(
        out,
        "\nruntime: {:.1} ns per frame per instance, {} ns per joint ({joints} animated joints), {:.3} ns per channel",
        frame,
        row.ns_per_joint.map_or("-".into(), |j| format!("{j:.2}")),
        rt
    )?;
    if let Some(p) = row.parallel_speedup {
        writeln!(
            out,
            "rayon: {:.2}x one thread, on {} thread(s){}",
            p,
            pool.current_num_threads(),
            row.threads_speedup.map_or(String::new(), |c| format!(
                " (plain threads with no per-frame sync, same run: {c:.2}x)"
            ))
        )?;
    }
    writeln!(out, "bytes: {} compiled", mb(row.bytes))?;
    io::stdout().lock().write_all(out.as_bytes())?;
    Ok(())
}

fn plot(args: &PlotArgs) -> Result<(), BoxError> {
    playable(&args.clip)?;
    if extension(&args.output) != "svg" {
        return Err(format!("{}: the output must end in .svg", args.output.display()).into());
    }
    if let (Some(a), Some(b)) = (args.from, args.to)
        && a.partial_cmp(&b) != Some(std::cmp::Ordering::Less)
    {
        return Err(format!("--from {a} --to {b}: the time range is empty").into());
    }
    for (name, v) in [("--from", args.from), ("--to", args.to)] {
        if v.is_some_and(|v| !v.is_finite()) {
            return Err(format!("{name} must be a finite number of seconds").into());
        }
    }
    if args.inbetweens.is_some_and(|n| n > 1000) {
        return Err("--inbetweens must be at most 1000".into());
    }
    let components = match args.components.as_deref() {
        Some(c) if args.path && !c.is_empty() => Some(tcb_plot::parse_components(c)?),
        _ => None,
    };
    let options = import_options(&args.clip, args.rotation, args.animation.as_ref())?;
    let (clip, skeleton) = load_any(&args.clip, &options)?;
    let mode = if args.path {
        // A rig's ground plane by default: x,z when Y is up.
        let components =
            components.unwrap_or_else(|| skeleton.as_ref().map_or([0, 1], tcb_plot::ground_plane));
        tcb_plot::Mode::Path { components }
    } else if args.velocity {
        tcb_plot::Mode::Velocity
    } else if args.speed {
        tcb_plot::Mode::Speed
    } else if args.components.is_some() {
        tcb_plot::Mode::Components
    } else {
        tcb_plot::Mode::Value
    };
    let file = args.clip.file_name().map_or_else(
        || args.clip.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let plot = tcb_plot::Plot {
        tracks: args.track.clone(),
        from: args.from,
        to: args.to,
        mode,
        inbetweens: args.inbetweens,
        ..tcb_plot::Plot::new(file)
    };
    let drawn = tcb_plot::render_with_notes(&clip, &plot)?;
    for note in &drawn.notes {
        eprintln!("tcb: {note}");
    }
    tcb_io::write_atomically(&args.output, drawn.svg.as_bytes())?;
    eprintln!("tcb: wrote {}", args.output.display());
    Ok(())
}

fn view_page(args: &ViewArgs) -> Result<(), BoxError> {
    playable(&args.clip)?;
    let file = args.clip.file_name().map_or_else(
        || args.clip.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let output = match &args.output {
        Some(o) => o.clone(),
        None => PathBuf::from(&file).with_extension("html"),
    };
    if extension(&output) != "html" {
        return Err(format!("{}: the output must end in .html", output.display()).into());
    }
    output_folder_exists(&output)?;
    let options = import_options(&args.clip, args.rotation, args.animation.as_ref())?;
    // A packed clip plays its own stream, as `sample` plays it.
    let (clip, skeleton, runtime) = if extension(&args.clip) == "tcbc" {
        let (clip, runtime) = load_tcbc(&args.clip)?;
        let skeleton = runtime.packed().and_then(|p| p.skeleton.clone());
        (clip, skeleton, runtime)
    } else {
        let (clip, skeleton) = load_any(&args.clip, &options)?;
        let runtime = std::sync::Arc::new(tcb_runtime::Clip::compile(&clip));
        (clip, skeleton, runtime)
    };
    let page = view::page(
        &clip,
        skeleton.as_ref(),
        runtime,
        &view::Options {
            title: file,
            fps: args.fps,
            joint: args.joint.clone(),
        },
    )?;
    for note in &page.notes {
        eprintln!("tcb: {note}");
    }
    tcb_io::write_atomically(&output, page.html.as_bytes())?;
    eprintln!(
        "tcb: wrote {} ({}): {}",
        output.display(),
        mb(page.html.len()),
        page.summary
    );
    Ok(())
}

fn figures(args: &FiguresArgs) -> Result<(), BoxError> {
    // Draw them all before creating or writing anything.
    let all = tcb_plot::figures()
        .into_iter()
        .map(|f| Ok((f.name, f.render(&args.root)?)))
        .collect::<Result<Vec<_>, tcb_plot::PlotError>>()?;
    std::fs::create_dir_all(&args.output).map_err(|e| format!("{}: {e}", args.output.display()))?;
    for (name, svg) in &all {
        tcb_io::write_atomically(args.output.join(name), svg.as_bytes())?;
    }
    eprintln!(
        "tcb: wrote {} figures to {}",
        all.len(),
        args.output.display()
    );
    Ok(())
}

fn sample(args: &SampleArgs) -> Result<(), BoxError> {
    playable(&args.clip)?;
    let (clip, packed) = if extension(&args.clip) == "tcbc" {
        let (clip, runtime) = load_tcbc(&args.clip)?;
        (clip, Some(runtime))
    } else {
        let loaded = load(&args.clip)?;
        warn(&loaded.warnings);
        (loaded.clip, None)
    };
    let times = sample_times(args, &clip)?;
    // Everything that can fail has been checked: from here on only writing can.
    let stdout = io::stdout().lock();
    let mut out = io::BufWriter::with_capacity(1 << 16, stdout);
    if args.scalar {
        write_csv(&mut out, &clip, &times, args.velocity, |t, v, d| {
            clip.sample_into(t, v, d)
        })?;
    } else {
        // Velocities printed are squad's own (the contract's numbers), not
        // the cubic's that a game loop plays (5e-5 of the speed off).
        let options = tcb_runtime::CompileOptions::default().exact_velocities(args.velocity);
        // A packed clip plays its own stream (its reference is `clip`).
        let runtime = packed.unwrap_or_else(|| {
            std::sync::Arc::new(tcb_runtime::Clip::compile_with(&clip, &options))
        });
        let mut instance = tcb_runtime::Instance::new(runtime);
        if args.velocity {
            instance = instance.with_velocities();
        }
        write_csv(&mut out, &clip, &times, args.velocity, |t, v, d| {
            instance.sample(t).write_row(v, d)
        })?;
    }
    out.flush()?;
    Ok(())
}

fn sample_times(args: &SampleArgs, clip: &SourceClip) -> Result<Vec<f64>, BoxError> {
    if args.fps.is_none() && (args.from.is_some() || args.to.is_some()) {
        return Err("--from and --to go with --fps".into());
    }
    if let Some(list) = &args.at {
        let times = list
            .split(',')
            .map(|s| {
                let s = s.trim();
                s.parse::<f64>()
                    .map_err(|_| format!("--at: \"{s}\" is not a number"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        return Ok(times);
    }
    let (first, last) = clip.time_range().ok_or("the clip has no tracks")?;
    if let Some(fps) = args.fps {
        let from = args.from.unwrap_or(first);
        let to = args.to.unwrap_or(last);
        if !(fps > 0.0 && fps.is_finite()) {
            return Err(format!("--fps must be a positive number, got {fps}").into());
        }
        if !from.is_finite() || !to.is_finite() {
            return Err("--from and --to must be finite".into());
        }
        if to < from {
            return Err(format!("--to {to} is before --from {from}").into());
        }
        match frame_count(from, to, fps) {
            Some(n) if n <= MAX_SAMPLES => {}
            Some(n) => {
                return Err(format!("{n} sample times requested; at most {MAX_SAMPLES}").into());
            }
            None => {
                let fps = if fps >= 1e15 {
                    format!("{fps:e}")
                } else {
                    format!("{fps}")
                };
                return Err(format!(
                    "--fps {fps} over {from} to {to} s asks for more than {MAX_SAMPLES} sample times"
                )
                .into());
            }
        }
        return Ok(frame_times(from, to, fps).collect());
    }
    let n = args.inbetweens.unwrap_or(0);
    let keys = clip.key_times();
    let total = (keys.len() as u64).saturating_mul(u64::from(n) + 1);
    if total > MAX_SAMPLES {
        return Err(format!("{total} sample times requested; at most {MAX_SAMPLES}").into());
    }
    Ok(inbetweens(&keys, n as usize))
}

/// Write the CSV, sampling each time with `sample(time, values, velocities)`.
fn write_csv(
    out: &mut impl Write,
    clip: &SourceClip,
    times: &[f64],
    velocity: bool,
    mut sample: impl FnMut(f64, &mut [f32], Option<&mut [f32]>),
) -> io::Result<()> {
    let names = clip.column_names();
    let mut header = String::from("time");
    for n in &names {
        header.push(',');
        header.push_str(n);
    }
    if velocity {
        for n in &names {
            header.push(',');
            header.push_str(n);
            header.push_str(".d");
        }
    }
    writeln!(out, "{header}")?;
    let channels = clip.channel_count();
    let mut values = vec![0.0f32; channels];
    let mut velocities = vec![0.0f32; channels];
    for &t in times {
        sample(t, &mut values, velocity.then_some(&mut velocities[..]));
        write!(out, "{t}")?;
        for v in &values {
            write!(out, ",{v}")?;
        }
        if velocity {
            for v in &velocities {
                write!(out, ",{v}")?;
            }
        }
        writeln!(out)?;
    }
    Ok(())
}
