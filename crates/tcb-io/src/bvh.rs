//! BVH motion capture: the hierarchy and the motion, as files in the wild
//! write them (CRLF, tabs, trailing blank lines, `Frames:` counts that
//! disagree with the rows).
//!
//! ```
//! let text = "HIERARCHY\nROOT hip\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.5\n0 0 0 0 0 0\n1 2 3 90 0 0\n";
//! let bvh = tcb_io::bvh::Bvh::parse(text)?;
//! assert_eq!(bvh.frame_count(), 2);
//! let doc = bvh.to_clip_doc("walk", tcb_core::RotationMode::Squad)?;
//! assert_eq!(doc.tracks[0].name, "hip.translation");
//! assert_eq!(doc.tracks[1].name, "hip.rotation");
//! assert_eq!(doc.tracks[1].times, [0.0, 0.5]);
//! # Ok::<(), tcb_io::Error>(())
//! ```

use crate::clip_json::{ClipDoc, SettingsDoc, TrackDoc};
use crate::error::Error;
use glam::{DQuat, DVec3, Vec3};
use tcb_core::skeleton::{Joint, Skeleton, Transform};
use tcb_core::{RotationMode, TrackKind};

/// One BVH channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// `Xposition`, `Yposition`, `Zposition` (axis 0, 1, 2).
    Position(usize),
    /// `Xrotation`, `Yrotation`, `Zrotation`, in degrees (axis 0, 1, 2).
    Rotation(usize),
}

impl Channel {
    fn parse(name: &str) -> Option<Channel> {
        let lower = name.to_ascii_lowercase();
        let axis = match lower.as_bytes().first()? {
            b'x' => 0,
            b'y' => 1,
            b'z' => 2,
            _ => return None,
        };
        match &lower[1..] {
            "position" => Some(Channel::Position(axis)),
            "rotation" => Some(Channel::Rotation(axis)),
            _ => None,
        }
    }
}

/// The deepest joint hierarchy [`Bvh::parse`] reads: joints nested
/// deeper are refused (nothing here recurses on the depth, but no rig is
/// more than tens of joints deep, and a file that claims otherwise is not
/// one).
pub const MAX_DEPTH: usize = 1024;

/// A parsed BVH file ([`Bvh::parse`]; its parts are read through
/// accessors, so that every `Bvh` is one the parser checked: a channel
/// list per joint, whole rows of values).
#[derive(Clone, Debug)]
pub struct Bvh {
    skeleton: Skeleton,
    channels: Vec<Vec<Channel>>,
    end_sites: Vec<(usize, Vec3)>,
    frame_time: f64,
    values: Vec<f32>,
    warnings: Vec<String>,
}

/// Tokens of the hierarchy with their 1-based lines.
struct Tokens<'a> {
    tokens: Vec<(usize, &'a str)>,
    at: usize,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    fn next(&mut self) -> Option<(usize, &'a str)> {
        let t = self.tokens.get(self.at).copied();
        self.at += 1;
        t
    }

    fn expect(&mut self, what: &str) -> Result<(usize, &'a str), Error> {
        self.next().ok_or_else(|| {
            Error::syntax(
                self.last_line,
                format!("the hierarchy ends where {what} was expected"),
            )
        })
    }

    fn number(&mut self, what: &str) -> Result<f32, Error> {
        let (line, tok) = self.expect(what)?;
        match tok.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(Error::syntax(
                line,
                format!("'{tok}' is not a finite number ({what})"),
            )),
        }
    }

    fn offset(&mut self) -> Result<Vec3, Error> {
        Ok(Vec3::new(
            self.number("OFFSET x")?,
            self.number("OFFSET y")?,
            self.number("OFFSET z")?,
        ))
    }
}

/// A byte-order mark, which some Windows editors write before `HIERARCHY`.
const BOM: &str = "\u{feff}";

/// `bytes` as BVH text. Bytes that are not UTF-8 are "not a BVH file"
/// unless the file starts with `HIERARCHY` (after a byte-order mark and
/// white space): then they are an error at their line (a Latin-1 joint
/// name, say).
pub(crate) fn text(bytes: &[u8]) -> Result<&str, Error> {
    std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let what = format!("byte 0x{:02X} at offset {at} is not UTF-8", bytes[at]);
        let start = bytes.strip_prefix(BOM.as_bytes()).unwrap_or(bytes);
        let start = start.trim_ascii_start();
        if start.starts_with(b"HIERARCHY") {
            let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
            Error::syntax(line, format!("{what} (BVH is read as UTF-8 text)"))
        } else {
            Error::import(format!("not a BVH file: not text ({what})"))
        }
    })
}

/// The first word of `text` is `HIERARCHY`, or the text is "not a BVH
/// file" (rather than, say, "no MOTION section" for a JSON file).
fn check_hierarchy_first(text: &str) -> Result<(), Error> {
    match text.split_whitespace().next() {
        Some("HIERARCHY") => Ok(()),
        Some(word) => {
            let mut shown: String = word.chars().take(20).collect();
            if shown.len() < word.len() {
                shown.push('…');
            }
            Err(Error::import(format!(
                "not a BVH file: it starts with '{shown}', not HIERARCHY"
            )))
        }
        None => Err(Error::import("not a BVH file: it is empty")),
    }
}

/// The name after `ROOT` or `JOINT` (`tok`, on `line`; the rest of the
/// line up to `{`) and the `{` after it; a ROOT only outside every joint
/// (`outside`), a JOINT only inside one, each name once (`names`).
fn joint_name(
    t: &mut Tokens,
    line: usize,
    tok: &str,
    outside: bool,
    names: &mut std::collections::HashSet<String>,
) -> Result<String, Error> {
    if (tok == "ROOT") != outside {
        let msg = if tok == "ROOT" {
            "ROOT inside a joint (use JOINT)"
        } else {
            "JOINT outside any ROOT"
        };
        return Err(Error::syntax(line, msg));
    }
    let mut name = Vec::new();
    while let Some(&(l, w)) = t.tokens.get(t.at) {
        if l != line || w == "{" {
            break;
        }
        name.push(w);
        t.at += 1;
    }
    let name = name.join(" ");
    if name.is_empty() {
        return Err(Error::syntax(line, format!("{tok} without a name")));
    }
    if !names.insert(name.clone()) {
        return Err(Error::syntax(
            line,
            format!("a second joint named '{name}'"),
        ));
    }
    match t.expect("'{'")? {
        (_, "{") => Ok(name),
        (l, w) => Err(Error::syntax(l, format!("expected '{{', found '{w}'"))),
    }
}

/// The count and names after `CHANNELS`: at most 6, none twice.
fn channel_list(t: &mut Tokens) -> Result<Vec<Channel>, Error> {
    let (l, n) = t.expect("the channel count")?;
    let n: usize = n
        .parse()
        .map_err(|_| Error::syntax(l, format!("'{n}' is not a channel count")))?;
    if n > 6 {
        return Err(Error::syntax(
            l,
            format!("CHANNELS {n}: at most 6 (X/Y/Z position and rotation)"),
        ));
    }
    let mut channels = Vec::with_capacity(n);
    for _ in 0..n {
        let (l, name) = t.expect("a channel name")?;
        let c = Channel::parse(name).ok_or_else(|| {
            Error::syntax(
                l,
                format!("unknown channel '{name}' (expected Xposition … Zrotation)"),
            )
        })?;
        if channels.contains(&c) {
            return Err(Error::syntax(l, format!("channel '{name}' listed twice")));
        }
        channels.push(c);
    }
    Ok(channels)
}

/// The rest of `End Site { OFFSET x y z }` after `End`: its offset.
fn end_site(t: &mut Tokens) -> Result<Vec3, Error> {
    for want in ["Site", "{", "OFFSET"] {
        let (l, w) = t.expect(want)?;
        if w != want {
            return Err(Error::syntax(
                l,
                format!("expected '{want}' in End Site, found '{w}'"),
            ));
        }
    }
    let offset = t.offset()?;
    match t.expect("'}'")? {
        (_, "}") => Ok(offset),
        (l, w) => Err(Error::syntax(
            l,
            format!("expected '}}' closing End Site, found '{w}'"),
        )),
    }
}

impl Bvh {
    /// Parse BVH text (a leading byte-order mark is skipped).
    pub fn parse(text: &str) -> Result<Bvh, Error> {
        let text = text.strip_prefix(BOM).unwrap_or(text);
        check_hierarchy_first(text)?;
        let lines: Vec<&str> = text.lines().collect();
        let motion = lines
            .iter()
            .position(|l| l.split_whitespace().next() == Some("MOTION"))
            .ok_or_else(|| Error::syntax(lines.len().max(1), "no MOTION section"))?;
        let mut tokens = Tokens {
            tokens: lines[..motion]
                .iter()
                .enumerate()
                .flat_map(|(i, l)| l.split_whitespace().map(move |t| (i + 1, t)))
                .collect(),
            at: 0,
            last_line: motion + 1,
        };
        let mut bvh = Bvh {
            skeleton: Skeleton::default(),
            channels: Vec::new(),
            end_sites: Vec::new(),
            frame_time: 0.0,
            values: Vec::new(),
            warnings: Vec::new(),
        };
        bvh.parse_hierarchy(&mut tokens)?;
        bvh.parse_motion(&lines, motion)?;
        Ok(bvh)
    }

    /// The `HIERARCHY` section: joints, their offsets and channels, End Sites.
    fn parse_hierarchy(&mut self, t: &mut Tokens) -> Result<(), Error> {
        // `HIERARCHY`, checked by `parse`.
        t.next();
        // Joints open and not yet closed.
        let mut stack: Vec<usize> = Vec::new();
        // Names so far (a search of the joints per joint is quadratic in a
        // wide hierarchy).
        let mut names = std::collections::HashSet::new();
        while let Some((line, tok)) = t.next() {
            let open = |what: &str| {
                stack
                    .last()
                    .copied()
                    .ok_or_else(|| Error::syntax(line, format!("{what} outside a joint")))
            };
            match tok {
                "ROOT" | "JOINT" => {
                    let name = joint_name(t, line, tok, stack.is_empty(), &mut names)?;
                    self.open_joint(name, line, &mut stack)?;
                }
                "OFFSET" => {
                    let j = open("OFFSET")?;
                    let offset = t.offset()?;
                    if let Some(rest) = self.skeleton.rest_mut(j) {
                        rest.translation = offset;
                    }
                }
                "CHANNELS" => {
                    let j = open("CHANNELS")?;
                    self.channels[j] = channel_list(t)?;
                }
                "End" => {
                    let j = open("End Site")?;
                    self.end_sites.push((j, end_site(t)?));
                }
                "}" => {
                    if stack.pop().is_none() {
                        return Err(Error::syntax(line, "'}' without a joint to close"));
                    }
                }
                other => {
                    return Err(Error::syntax(
                        line,
                        format!("unexpected '{other}' in the hierarchy"),
                    ));
                }
            }
        }
        self.check_hierarchy(t, &stack)
    }

    /// Adds joint `name` as a child of the innermost open joint and opens it.
    fn open_joint(
        &mut self,
        name: String,
        line: usize,
        stack: &mut Vec<usize>,
    ) -> Result<(), Error> {
        if stack.len() == MAX_DEPTH {
            return Err(Error::syntax(
                line,
                format!("joints nested deeper than {MAX_DEPTH} (the limit; rigs are tens deep)"),
            ));
        }
        let joint = Joint {
            name,
            parent: stack.last().copied(),
            rest: Transform::IDENTITY,
        };
        let at = self
            .skeleton
            .push(joint)
            .expect("a joint's parent is the joint open around it, before it");
        self.channels.push(Vec::new());
        stack.push(at);
        Ok(())
    }

    /// The end of the hierarchy: every joint closed, a root, some channels.
    fn check_hierarchy(&self, t: &Tokens, stack: &[usize]) -> Result<(), Error> {
        if !stack.is_empty() {
            return Err(Error::syntax(
                t.last_line,
                "the hierarchy ends with joints not closed by '}'",
            ));
        }
        if self.skeleton.joints().is_empty() {
            return Err(Error::syntax(t.last_line, "no ROOT joint"));
        }
        if self.channel_count() == 0 {
            return Err(Error::syntax(t.last_line, "no joint has CHANNELS"));
        }
        Ok(())
    }

    /// The `MOTION` section after line `motion`: its header, then one row per frame.
    fn parse_motion(&mut self, lines: &[&str], motion: usize) -> Result<(), Error> {
        // (1-based line, text) of the non-blank lines after MOTION.
        let mut rest = lines
            .iter()
            .enumerate()
            .skip(motion + 1)
            .map(|(i, l)| (i + 1, l.trim()))
            .filter(|(_, l)| !l.is_empty());
        let mut header = |key: &str| -> Result<(usize, String), Error> {
            let (line, text) = rest.next().ok_or_else(|| {
                Error::syntax(lines.len(), format!("'{key}' missing after MOTION"))
            })?;
            let value = text
                .split_once(':')
                .filter(|(k, _)| k.split_whitespace().collect::<Vec<_>>().join(" ") == key)
                .map(|(_, v)| v.trim().to_string())
                .ok_or_else(|| {
                    Error::syntax(line, format!("expected '{key}: …', found '{text}'"))
                })?;
            Ok((line, value))
        };
        let (frames_line, frames) = header("Frames")?;
        let claimed: u64 = frames
            .parse()
            .map_err(|_| Error::syntax(frames_line, format!("'{frames}' is not a frame count")))?;
        let (line, dt) = header("Frame Time")?;
        self.frame_time = match dt.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => v,
            _ => {
                return Err(Error::syntax(
                    line,
                    format!("Frame Time '{dt}' is not a positive number of seconds"),
                ));
            }
        };
        let mut rows = 0usize;
        for (line, text) in rest {
            self.read_row(line, text, rows)?;
            rows += 1;
        }
        if claimed != rows as u64 {
            self.warnings.push(format!(
                "line {frames_line}: the header says Frames: {claimed} but {rows} rows follow; read the {rows} rows"
            ));
        }
        Ok(())
    }

    /// Frame `row`'s values, from `text` on `line`: one finite number per channel.
    fn read_row(&mut self, line: usize, text: &str, row: usize) -> Result<(), Error> {
        let width = self.channel_count();
        let before = self.values.len();
        for tok in text.split_whitespace() {
            if self.values.len() - before == width {
                return Err(Error::syntax(
                    line,
                    format!("frame {row} has more than {width} values (one per channel)"),
                ));
            }
            match tok.parse::<f32>() {
                Ok(v) if v.is_finite() => self.values.push(v),
                _ => {
                    let c = self.values.len() - before;
                    return Err(Error::syntax(
                        line,
                        format!(
                            "frame {row}, channel {c} ({}): '{tok}' is not a finite number",
                            self.channel_name(c)
                        ),
                    ));
                }
            }
        }
        let got = self.values.len() - before;
        if got != width {
            return Err(Error::syntax(
                line,
                format!(
                    "frame {row} has {got} values, expected {width} (truncated or malformed row)"
                ),
            ));
        }
        Ok(())
    }

    /// Joints (`ROOT` and `JOINT`, not `End Site`), rest translation =
    /// `OFFSET`, indexed as [`Self::channels`] and [`Self::local`] index
    /// them. [`crate::load`] and [`Self::to_clip_doc`] give
    /// [`Self::skeleton_with_end_sites`] instead: these joints at the same
    /// indices, then a leaf joint per End Site.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Channels of each joint, in the order listed.
    pub fn channels(&self) -> &[Vec<Channel>] {
        &self.channels
    }

    /// `End Site`s: the parent joint and the offset.
    pub fn end_sites(&self) -> &[(usize, Vec3)] {
        &self.end_sites
    }

    /// `Frame Time`, seconds.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Channel values, one row per frame, channels in hierarchy order.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Things that were read but look wrong (a `Frames:` count that
    /// disagrees with the rows).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Number of channels (values per frame).
    pub fn channel_count(&self) -> usize {
        self.channels.iter().map(Vec::len).sum()
    }

    /// Number of frames read.
    pub fn frame_count(&self) -> usize {
        self.values.len() / self.channel_count().max(1)
    }

    fn channel_name(&self, mut c: usize) -> String {
        for (j, ch) in self.channels.iter().enumerate() {
            if c < ch.len() {
                let (kind, axis) = match ch[c] {
                    Channel::Position(a) => ("position", a),
                    Channel::Rotation(a) => ("rotation", a),
                };
                return format!(
                    "{} {}{kind}",
                    self.skeleton.joints()[j].name,
                    ["X", "Y", "Z"][axis]
                );
            }
            c -= ch.len();
        }
        String::new()
    }

    /// The local translation and rotation of `joint` in `frame`: position
    /// channels as written (the `OFFSET` on axes without one), rotation
    /// channels composed in the order listed (`Zrotation Xrotation
    /// Yrotation` is `qz * qx * qy`), in f64; `None` beyond the frames or
    /// the joints.
    pub fn local(&self, frame: usize, joint: usize) -> Option<(DVec3, DQuat)> {
        if frame >= self.frame_count() || joint >= self.skeleton.joints().len() {
            return None;
        }
        let first: usize = self.channels[..joint].iter().map(Vec::len).sum();
        Some(self.local_at(frame * self.channel_count(), first, joint))
    }

    /// [`Self::local`] of the frame whose row starts at value `row` and of
    /// the joint whose channels start at `first` in it.
    fn local_at(&self, row: usize, first: usize, joint: usize) -> (DVec3, DQuat) {
        let row = &self.values[row..];
        let mut t = self.skeleton.joints()[joint].rest.translation.as_dvec3();
        let mut q = DQuat::IDENTITY;
        for (i, c) in self.channels[joint].iter().enumerate() {
            let v = f64::from(row[first + i]);
            match *c {
                Channel::Position(a) => t[a] = v,
                Channel::Rotation(a) => {
                    let axis = [DVec3::X, DVec3::Y, DVec3::Z][a];
                    q *= DQuat::from_axis_angle(axis, v.to_radians());
                }
            }
        }
        (t, q.normalize())
    }

    /// The clip: per joint, `<joint>.translation` (vec3) if it has position
    /// channels and `<joint>.rotation` (quat, `rotation` mode) if it has
    /// rotation channels, one key per frame at `frame * Frame Time`.
    pub fn to_clip_doc(&self, name: &str, rotation: RotationMode) -> Result<ClipDoc, Error> {
        let frames = self.frame_count();
        if frames < 2 {
            return Err(Error::import(format!(
                "{frames} frame(s) of motion: a clip needs at least 2"
            )));
        }
        let times: Vec<f64> = (0..frames).map(|f| f as f64 * self.frame_time).collect();
        let mut tracks = Vec::new();
        let count = self.channel_count();
        let mut first = 0;
        for (j, joint) in self.skeleton.joints().iter().enumerate() {
            let ch = &self.channels[j];
            let at = first;
            first += ch.len();
            let has_pos = ch.iter().any(|c| matches!(c, Channel::Position(_)));
            let has_rot = ch.iter().any(|c| matches!(c, Channel::Rotation(_)));
            let track = |suffix: &str, kind: TrackKind, values: Vec<[f32; 4]>| TrackDoc {
                name: format!("{}.{suffix}", joint.name),
                kind,
                times: times.clone(),
                values,
                keys: Vec::new(),
                settings: SettingsDoc::default(),
            };
            if !has_pos && !has_rot {
                continue;
            }
            // Each frame's local transform once, for both tracks.
            let locals: Vec<(DVec3, DQuat)> = (0..frames)
                .map(|f| self.local_at(f * count, at, j))
                .collect();
            if has_pos {
                let values = locals
                    .iter()
                    .map(|(t, _)| {
                        let t = t.as_vec3();
                        [t.x, t.y, t.z, 0.0]
                    })
                    .collect();
                tracks.push(track("translation", TrackKind::Vec3, values));
            }
            if has_rot {
                let values = locals.iter().map(|(_, q)| q.as_quat().to_array()).collect();
                tracks.push(track("rotation", TrackKind::Quat, values));
            }
        }
        Ok(ClipDoc {
            name: name.to_string(),
            defaults: SettingsDoc {
                rotation: Some(rotation),
                ..SettingsDoc::default()
            },
            tracks,
            skeleton: Some(self.skeleton_with_end_sites()),
        })
    }

    /// The skeleton with each End Site as a leaf joint named
    /// `<parent>_end` (clip-format.md), so that tools composing the rig
    /// reach the ends of its chains (`<parent>_end2`, ... when a joint has
    /// several, or the name is taken): [`Self::skeleton`]'s joints at the
    /// same indices, then the End Sites in file order. What [`crate::load`]
    /// gives.
    pub fn skeleton_with_end_sites(&self) -> Skeleton {
        let mut out = self.skeleton.clone();
        let mut names: std::collections::HashSet<String> =
            out.joints().iter().map(|j| j.name.clone()).collect();
        for &(parent, offset) in &self.end_sites {
            let base = format!("{}_end", self.skeleton.joints()[parent].name);
            let mut name = base.clone();
            let mut n = 1;
            while names.contains(&name) {
                n += 1;
                name = format!("{base}{n}");
            }
            names.insert(name.clone());
            out.push(Joint {
                name,
                parent: Some(parent),
                rest: Transform {
                    translation: offset,
                    ..Transform::IDENTITY
                },
            })
            .expect("an End Site's parent is a joint before it");
        }
        out
    }
}
