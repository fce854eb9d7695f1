//! The clip file, format `tcb-clip/1` (the project's `docs/clip-format.md`).
//!
//! [`ClipDoc`] is the file as written: every optional field stays optional,
//! so a clip read and written again says no more than it said. [`ClipDoc::build`]
//! resolves defaults and builds the validated [`tcb_core::Clip`].
//!
//! Parsing is strict: unknown fields are errors (a misspelt `tangent_rule`
//! would otherwise silently give another curve), except `extras`, which any
//! object may carry for the user's own data, as in glTF.

use crate::error::{Error, ErrorKind, Location};
use glam::{Quat, Vec2, Vec3, Vec4};
use serde_json::{Map, Value as Json};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;
use std::str::FromStr;
use tcb_core::skeleton::Skeleton;
use tcb_core::{
    Clip, Ease, Ends, Extrapolation, Hemisphere, Interp, KeyParams, NamedTrack, RotationMode,
    RotationTrack, TangentRule, Tcb, Track, TrackData, TrackKind, TrackSettings, Value,
};

/// The format string a clip file carries.
pub const FORMAT: &str = "tcb-clip/1";

/// Track settings as a file states them: `defaults`, or a track's overrides.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SettingsDoc {
    /// `tangent_rule`.
    pub tangent_rule: Option<TangentRule>,
    /// `ends`.
    pub ends: Option<Ends>,
    /// `match_speed`.
    pub match_speed: Option<bool>,
    /// `continuity_fade`.
    pub continuity_fade: Option<bool>,
    /// `tcb`: the default `[t, c, b]` of keys that do not state one.
    pub tcb: Option<[f64; 3]>,
    /// `pre`.
    pub pre: Option<Extrapolation>,
    /// `post`.
    pub post: Option<Extrapolation>,
    /// `rotation` (quat tracks).
    pub rotation: Option<RotationMode>,
    /// `hemisphere` (quat tracks): `nearest` or `keep`.
    pub hemisphere: Option<Hemisphere>,
}

impl SettingsDoc {
    const FIELDS: [&'static str; 9] = [
        "tangent_rule",
        "ends",
        "match_speed",
        "continuity_fade",
        "tcb",
        "pre",
        "post",
        "rotation",
        "hemisphere",
    ];

    /// These settings, with any field they leave out taken from `base`.
    pub fn or(&self, base: &SettingsDoc) -> SettingsDoc {
        SettingsDoc {
            tangent_rule: self.tangent_rule.or(base.tangent_rule),
            ends: self.ends.or(base.ends),
            match_speed: self.match_speed.or(base.match_speed),
            continuity_fade: self.continuity_fade.or(base.continuity_fade),
            tcb: self.tcb.or(base.tcb),
            pre: self.pre.or(base.pre),
            post: self.post.or(base.post),
            rotation: self.rotation.or(base.rotation),
            hemisphere: self.hemisphere.or(base.hemisphere),
        }
    }

    /// The track settings and the default key TCB, with contract defaults
    /// for whatever is left out.
    pub fn resolve(&self) -> (TrackSettings, Tcb) {
        let d = TrackSettings::default();
        let settings = TrackSettings {
            tangent_rule: self.tangent_rule.unwrap_or(d.tangent_rule),
            ends: self.ends.unwrap_or(d.ends),
            match_speed: self.match_speed.unwrap_or(d.match_speed),
            continuity_fade: self.continuity_fade.unwrap_or(d.continuity_fade),
            pre: self.pre.unwrap_or(d.pre),
            post: self.post.unwrap_or(d.post),
            rotation: self.rotation.unwrap_or(d.rotation),
            hemisphere: self.hemisphere.unwrap_or(d.hemisphere),
        };
        (settings, self.tcb.map_or(Tcb::DEFAULT, Tcb::from_array))
    }
}

/// One entry of a track's `keys`.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct KeyDoc {
    /// `tcb`: `[t, c, b]`.
    pub tcb: Option<[f64; 3]>,
    /// `ease`: `[to, from]`.
    pub ease: Option<[f64; 2]>,
    /// `interp`.
    pub interp: Option<Interp>,
    /// `in`: explicit incoming tangent, value per second (components padded to 4).
    pub tangent_in: Option<[f32; 4]>,
    /// `out`: explicit outgoing tangent.
    pub tangent_out: Option<[f32; 4]>,
}

impl KeyDoc {
    fn is_empty(&self) -> bool {
        *self == KeyDoc::default()
    }
}

/// One track as the file states it.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackDoc {
    /// `name`.
    pub name: String,
    /// `kind`.
    pub kind: TrackKind,
    /// `times` (seconds).
    pub times: Vec<f64>,
    /// `values`, each padded to 4 components (`kind.dim()` are used).
    pub values: Vec<[f32; 4]>,
    /// `keys` (empty when absent).
    pub keys: Vec<KeyDoc>,
    /// Per-track overrides of `defaults`.
    pub settings: SettingsDoc,
}

/// A clip file as written.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ClipDoc {
    /// `name`.
    pub name: String,
    /// `defaults`.
    pub defaults: SettingsDoc,
    /// `tracks`, in file order.
    pub tracks: Vec<TrackDoc>,
    /// `skeleton`: the rig the clip animates (BVH and glTF imports fill it).
    pub skeleton: Option<Skeleton>,
}

/// Read, parse and build the clip at `path`.
///
/// ```no_run
/// let clip = tcb_io::load_clip("examples/clips/bounce.json".as_ref())?;
/// println!("{} channels", clip.channel_count());
/// # Ok::<(), tcb_io::Error>(())
/// ```
pub fn load_clip(path: &Path) -> Result<Clip, Error> {
    let doc = read_clip_doc(path)?;
    doc.build().map_err(|e| e.in_file(path))
}

/// Read and parse the clip file at `path` without building it (files
/// above [`crate::DEFAULT_MAX_FILE_BYTES`] are refused unread).
pub fn read_clip_doc(path: &Path) -> Result<ClipDoc, Error> {
    read_clip_doc_limited(path, crate::DEFAULT_MAX_FILE_BYTES)
}

/// [`read_clip_doc`] with its own file size limit.
pub(crate) fn read_clip_doc_limited(path: &Path, limit: u64) -> Result<ClipDoc, Error> {
    let text = crate::read_text_limited(path, limit)?;
    ClipDoc::parse(&text).map_err(|e| e.in_file(path))
}

/// Write `doc` to `path`: to a temporary file beside it, then renamed over
/// it, so that a failure leaves no half-written clip.
pub fn write_clip_doc(doc: &ClipDoc, path: &Path) -> Result<(), Error> {
    crate::write_atomically(path, doc.to_json().as_bytes())
}

impl ClipDoc {
    /// Parse clip JSON. Errors carry the track and key, not the file.
    pub fn parse(text: &str) -> Result<Self, Error> {
        let json = parse_json(text)?;
        let top = Location::default();
        let obj = as_object(&json, &top, "the clip")?;
        check_fields(
            obj,
            &["format", "name", "defaults", "tracks", "skeleton"],
            &top,
            "the clip",
        )?;
        match obj.get("format") {
            Some(Json::String(f)) if f == FORMAT => {}
            Some(other) => {
                return Err(Error::invalid(
                    top,
                    format!("format is {other}, expected \"{FORMAT}\""),
                ));
            }
            None => {
                return Err(Error::invalid(
                    top,
                    format!("missing \"format\": \"{FORMAT}\""),
                ));
            }
        }
        let name = match obj.get("name") {
            None => String::new(),
            Some(v) => as_str(v, &top, "name")?.to_owned(),
        };
        let defaults = match obj.get("defaults") {
            None => SettingsDoc::default(),
            Some(v) => {
                let d = as_object(v, &top, "defaults")?;
                check_fields(d, &SettingsDoc::FIELDS, &top, "defaults")?;
                parse_settings(d, &top)?
            }
        };
        let tracks = match obj.get("tracks") {
            Some(Json::Array(a)) => a,
            Some(_) => return Err(Error::invalid(top, "tracks must be an array")),
            None => return Err(Error::invalid(top, "missing \"tracks\"")),
        };
        let tracks = tracks
            .iter()
            .enumerate()
            .map(|(i, t)| parse_track(i, t))
            .collect::<Result<Vec<_>, _>>()?;
        let skeleton = match obj.get("skeleton") {
            None => None,
            Some(v) => Some(crate::skeleton_json::parse(v)?),
        };
        Ok(ClipDoc {
            name,
            defaults,
            tracks,
            skeleton,
        })
    }

    /// Resolve defaults and build every track. Errors name the track and key.
    pub fn build(&self) -> Result<Clip, Error> {
        let mut seen: HashMap<&str, usize> = HashMap::new();
        let mut tracks = Vec::with_capacity(self.tracks.len());
        for (i, t) in self.tracks.iter().enumerate() {
            let loc = Location {
                track: Some(quote(&t.name)),
                ..Location::default()
            };
            if let Some(first) = seen.insert(&t.name, i) {
                return Err(Error::invalid(
                    loc,
                    format!("the name is already used by track {first}"),
                ));
            }
            let data = t.build(&self.defaults).map_err(|e| Error {
                location: Location {
                    key: e.key(),
                    ..loc
                },
                kind: ErrorKind::Track(e),
            })?;
            tracks.push(NamedTrack {
                name: t.name.clone(),
                data,
            });
        }
        // Names were checked above, with the track that repeats one.
        Clip::new(self.name.clone(), tracks).map_err(|e| {
            Error::invalid(
                Location {
                    track: Some(quote(&e.0)),
                    ..Location::default()
                },
                "the name is already used".to_string(),
            )
        })
    }

    /// The clip as JSON text: one line per field of a track, so that large
    /// clips stay readable and diffable. Numbers are written in their
    /// shortest round-trip form.
    pub fn to_json(&self) -> String {
        let mut out = String::new();
        out.push_str("{\n");
        let _ = writeln!(out, "  \"format\": \"{FORMAT}\",");
        let _ = writeln!(out, "  \"name\": {},", json_str(&self.name));
        let defaults = settings_json(&self.defaults);
        if !defaults.is_empty() {
            let _ = writeln!(out, "  \"defaults\": {{{}}},", defaults.join(", "));
        }
        if let Some(skeleton) = &self.skeleton {
            crate::skeleton_json::write(skeleton, &mut out);
        }
        out.push_str("  \"tracks\": [");
        for (i, t) in self.tracks.iter().enumerate() {
            out.push_str(if i == 0 { "\n" } else { ",\n" });
            t.write_json(&mut out);
        }
        out.push_str(if self.tracks.is_empty() {
            "]\n}\n"
        } else {
            "\n  ]\n}\n"
        });
        out
    }
}

impl TrackDoc {
    /// Build the track with `defaults` under this track's overrides.
    pub fn build(&self, defaults: &SettingsDoc) -> Result<TrackData, tcb_core::TrackError> {
        let (settings, tcb) = self.settings.or(defaults).resolve();
        /// Per-key parameters; without `keys`, every key takes the track's default tcb.
        fn params<V: Copy>(
            t: &TrackDoc,
            tcb: Tcb,
            conv: impl Fn([f32; 4]) -> V,
        ) -> Vec<KeyParams<V>> {
            if t.keys.is_empty() {
                return vec![KeyParams::with_tcb(tcb); t.times.len()];
            }
            t.keys
                .iter()
                .map(|k| KeyParams {
                    tcb: k.tcb.map_or(tcb, Tcb::from_array),
                    ease: k.ease.map_or(Ease::NONE, Ease::from_array),
                    interp: k.interp.unwrap_or_default(),
                    tangent_in: k.tangent_in.map(&conv),
                    tangent_out: k.tangent_out.map(&conv),
                })
                .collect()
        }
        fn vector<V: Value>(
            t: &TrackDoc,
            tcb: Tcb,
            settings: &TrackSettings,
        ) -> Result<Track<V>, tcb_core::TrackError> {
            let values = t.values.iter().map(|&a| V::from_array(a)).collect();
            Track::new(
                t.times.clone(),
                values,
                params(t, tcb, V::from_array),
                settings,
            )
        }
        Ok(match self.kind {
            TrackKind::Scalar => TrackData::Scalar(vector(self, tcb, &settings)?),
            TrackKind::Vec2 => TrackData::Vec2(vector::<Vec2>(self, tcb, &settings)?),
            TrackKind::Vec3 => TrackData::Vec3(vector::<Vec3>(self, tcb, &settings)?),
            TrackKind::Vec4 => TrackData::Vec4(vector::<Vec4>(self, tcb, &settings)?),
            TrackKind::Quat => {
                let values = self.values.iter().map(|&a| Quat::from_array(a)).collect();
                let keys = params(self, tcb, Quat::from_array);
                TrackData::Quat(RotationTrack::new(
                    self.times.clone(),
                    values,
                    keys,
                    &settings,
                )?)
            }
        })
    }

    fn write_json(&self, out: &mut String) {
        let dim = self.kind.dim();
        let value = |v: &[f32; 4]| {
            if self.kind == TrackKind::Scalar {
                num32(v[0])
            } else {
                format!(
                    "[{}]",
                    v[..dim]
                        .iter()
                        .map(|&x| num32(x))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            }
        };
        let _ = write!(
            out,
            "    {{\n      \"name\": {},\n      \"kind\": \"{}\",\n      \"times\": [{}],\n      \"values\": [{}]",
            json_str(&self.name),
            self.kind,
            self.times
                .iter()
                .map(|&t| num64(t))
                .collect::<Vec<_>>()
                .join(", "),
            self.values.iter().map(value).collect::<Vec<_>>().join(", "),
        );
        if self.keys.iter().any(|k| !k.is_empty()) {
            let keys: Vec<String> = self
                .keys
                .iter()
                .map(|k| {
                    let mut f = Vec::new();
                    if let Some(t) = k.tcb {
                        f.push(format!(
                            "\"tcb\": [{}, {}, {}]",
                            num64(t[0]),
                            num64(t[1]),
                            num64(t[2])
                        ));
                    }
                    if let Some(e) = k.ease {
                        f.push(format!("\"ease\": [{}, {}]", num64(e[0]), num64(e[1])));
                    }
                    if let Some(i) = k.interp {
                        f.push(format!("\"interp\": \"{i}\""));
                    }
                    if let Some(v) = &k.tangent_in {
                        f.push(format!("\"in\": {}", value(v)));
                    }
                    if let Some(v) = &k.tangent_out {
                        f.push(format!("\"out\": {}", value(v)));
                    }
                    format!("{{{}}}", f.join(", "))
                })
                .collect();
            let _ = write!(out, ",\n      \"keys\": [{}]", keys.join(", "));
        }
        for field in settings_json(&self.settings) {
            let _ = write!(out, ",\n      {field}");
        }
        out.push_str("\n    }");
    }
}

fn settings_json(s: &SettingsDoc) -> Vec<String> {
    let mut f = Vec::new();
    let mut text = |k: &str, v: Option<&str>| {
        if let Some(v) = v {
            f.push(format!("\"{k}\": \"{v}\""));
        }
    };
    text("tangent_rule", s.tangent_rule.map(|x| x.name()));
    text("ends", s.ends.map(|x| x.name()));
    text("pre", s.pre.map(|x| x.name()));
    text("post", s.post.map(|x| x.name()));
    text("rotation", s.rotation.map(|x| x.name()));
    text("hemisphere", s.hemisphere.map(|x| x.name()));
    if let Some(b) = s.match_speed {
        f.push(format!("\"match_speed\": {b}"));
    }
    if let Some(b) = s.continuity_fade {
        f.push(format!("\"continuity_fade\": {b}"));
    }
    if let Some(t) = s.tcb {
        f.push(format!(
            "\"tcb\": [{}, {}, {}]",
            num64(t[0]),
            num64(t[1]),
            num64(t[2])
        ));
    }
    f
}

/// Shortest round-trip form of an f32 (as JSON: `1` not `1.0` is fine).
pub(crate) fn num32(x: f32) -> String {
    format!("{x}")
}

fn num64(x: f64) -> String {
    format!("{x}")
}

pub(crate) fn json_str(s: &str) -> String {
    Json::String(s.to_owned()).to_string()
}

fn quote(name: &str) -> String {
    format!("'{name}'")
}

/// Marks a number token that overflows f64 (`1e999`), quoted so that the
/// document parses and the error can name its track and key.
const OVERFLOW: &str = "\u{0}overflow:";

/// JSON text to a value. serde_json refuses numbers beyond f64 as a syntax
/// error; those tokens are quoted with [`OVERFLOW`] and reported later, where
/// the track and key are known.
fn parse_json(text: &str) -> Result<Json, Error> {
    let mut text = std::borrow::Cow::Borrowed(text);
    // Each round quotes one token; the bound only guards against a loop.
    for _ in 0..64 {
        let e = match serde_json::from_str::<Json>(&text) {
            Ok(json) => return Ok(json),
            Err(e) => e,
        };
        if e.to_string().starts_with("number out of range")
            && let Some(quoted) = quote_number_at(&text, e.line(), e.column())
        {
            text = quoted.into();
            continue;
        }
        return Err(Error {
            location: Location::default(),
            kind: ErrorKind::Json {
                line: e.line(),
                column: e.column(),
                message: strip_position(&e.to_string()),
            },
        });
    }
    Err(Error::invalid(
        Location::default(),
        "too many numbers out of range",
    ))
}

/// `text` with the number token ending near `line`:`column` quoted.
fn quote_number_at(text: &str, line: usize, column: usize) -> Option<String> {
    let start_of_line: usize = text
        .split_inclusive('\n')
        .take(line - 1)
        .map(str::len)
        .sum();
    let at = (start_of_line + column).min(text.len());
    let is_num = |c: u8| c.is_ascii_digit() || matches!(c, b'e' | b'E' | b'+' | b'-' | b'.');
    let bytes = text.as_bytes();
    let mut end = at;
    while end > 0 && !is_num(bytes[end - 1]) {
        end -= 1;
    }
    while end < bytes.len() && is_num(bytes[end]) {
        end += 1;
    }
    let mut start = end;
    while start > 0 && is_num(bytes[start - 1]) {
        start -= 1;
    }
    (start < end).then(|| {
        format!(
            "{}\"\\u0000overflow:{}\"{}",
            &text[..start],
            &text[start..end],
            &text[end..]
        )
    })
}

/// serde_json appends " at line L column C"; we report those separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}

pub(crate) fn as_object<'a>(
    v: &'a Json,
    loc: &Location,
    what: &str,
) -> Result<&'a Map<String, Json>, Error> {
    v.as_object()
        .ok_or_else(|| Error::invalid(loc.clone(), format!("{what} must be a JSON object")))
}

pub(crate) fn as_str<'a>(v: &'a Json, loc: &Location, what: &str) -> Result<&'a str, Error> {
    v.as_str()
        .ok_or_else(|| Error::invalid(loc.clone(), format!("{what} must be a string, found {v}")))
}

fn as_bool(v: &Json, loc: &Location, what: &str) -> Result<bool, Error> {
    v.as_bool().ok_or_else(|| {
        Error::invalid(
            loc.clone(),
            format!("{what} must be true or false, found {v}"),
        )
    })
}

fn as_f64(v: &Json, loc: &Location, what: &str) -> Result<f64, Error> {
    if let Some(token) = v.as_str().and_then(|s| s.strip_prefix(OVERFLOW)) {
        return Err(Error::invalid(
            loc.clone(),
            format!("{what} {token} is not a finite number"),
        ));
    }
    v.as_f64()
        .ok_or_else(|| Error::invalid(loc.clone(), format!("{what} must be a number, found {v}")))
}

/// A JSON number that fits an f32 (finite after rounding).
pub(crate) fn as_f32(v: &Json, loc: &Location, what: &str) -> Result<f32, Error> {
    let x = as_f64(v, loc, what)? as f32;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::invalid(
            loc.clone(),
            format!("{what} {v} is not a finite f32"),
        ))
    }
}

pub(crate) fn as_array<'a>(v: &'a Json, loc: &Location, what: &str) -> Result<&'a [Json], Error> {
    v.as_array().map(Vec::as_slice).ok_or_else(|| {
        Error::invalid(
            loc.clone(),
            format!("{what} must be an array, found {}", brief(v)),
        )
    })
}

pub(crate) fn as_numbers<const N: usize>(
    v: &Json,
    loc: &Location,
    what: &str,
) -> Result<[f64; N], Error> {
    let a = as_array(v, loc, what)?;
    if a.len() != N {
        return Err(Error::invalid(
            loc.clone(),
            format!("{what} must have {N} numbers, found {}", a.len()),
        ));
    }
    let mut out = [0.0; N];
    for (o, x) in out.iter_mut().zip(a) {
        *o = as_f64(x, loc, what)?;
    }
    Ok(out)
}

fn as_enum<T: FromStr<Err = tcb_core::params::UnknownName>>(
    v: &Json,
    loc: &Location,
    what: &str,
) -> Result<T, Error> {
    let s = as_str(v, loc, what)?;
    s.parse()
        .map_err(|e| Error::invalid(loc.clone(), format!("unknown {what} \"{s}\" ({e})")))
}

/// A short rendering of a JSON value for messages.
fn brief(v: &Json) -> String {
    let s = v.to_string();
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(40).collect::<String>())
    } else {
        s
    }
}

pub(crate) fn check_fields(
    obj: &Map<String, Json>,
    allowed: &[&str],
    loc: &Location,
    what: &str,
) -> Result<(), Error> {
    for k in obj.keys() {
        if k != "extras" && !allowed.contains(&k.as_str()) {
            return Err(Error::invalid(
                loc.clone(),
                format!(
                    "unknown field \"{k}\" in {what} (expected one of: {})",
                    allowed.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

fn parse_settings(obj: &Map<String, Json>, loc: &Location) -> Result<SettingsDoc, Error> {
    let get = |k: &str| obj.get(k);
    Ok(SettingsDoc {
        tangent_rule: get("tangent_rule")
            .map(|v| as_enum(v, loc, "tangent_rule"))
            .transpose()?,
        ends: get("ends").map(|v| as_enum(v, loc, "ends")).transpose()?,
        match_speed: get("match_speed")
            .map(|v| as_bool(v, loc, "match_speed"))
            .transpose()?,
        continuity_fade: get("continuity_fade")
            .map(|v| as_bool(v, loc, "continuity_fade"))
            .transpose()?,
        tcb: get("tcb").map(|v| parse_tcb(v, loc)).transpose()?,
        pre: get("pre").map(|v| as_enum(v, loc, "pre")).transpose()?,
        post: get("post").map(|v| as_enum(v, loc, "post")).transpose()?,
        rotation: get("rotation")
            .map(|v| as_enum(v, loc, "rotation"))
            .transpose()?,
        hemisphere: get("hemisphere")
            .map(|v| as_enum(v, loc, "hemisphere"))
            .transpose()?,
    })
}

fn parse_tcb(v: &Json, loc: &Location) -> Result<[f64; 3], Error> {
    // JSON has no NaN or infinity, but 1e999 parses as infinity.
    let t = as_numbers::<3>(v, loc, "tcb")?;
    if t.iter().all(|x| x.is_finite()) {
        Ok(t)
    } else {
        Err(Error::invalid(
            loc.clone(),
            "tcb has a value that is not finite",
        ))
    }
}

/// A value of `kind`: a number for scalars, an array of `dim` numbers otherwise.
fn parse_value(v: &Json, kind: TrackKind, loc: &Location, what: &str) -> Result<[f32; 4], Error> {
    let mut out = [0.0f32; 4];
    if kind == TrackKind::Scalar {
        if v.is_array() {
            return Err(Error::invalid(
                loc.clone(),
                format!(
                    "{what} of a scalar track must be a number, found {}",
                    brief(v)
                ),
            ));
        }
        out[0] = as_f32(v, loc, what)?;
        return Ok(out);
    }
    let a = v.as_array().ok_or_else(|| {
        Error::invalid(
            loc.clone(),
            format!(
                "{what} of a {kind} track must be an array of {} numbers, found {}",
                kind.dim(),
                brief(v)
            ),
        )
    })?;
    if a.len() != kind.dim() {
        return Err(Error::invalid(
            loc.clone(),
            format!(
                "{what} of a {kind} track must have {} numbers, found {}",
                kind.dim(),
                a.len()
            ),
        ));
    }
    for (o, x) in out.iter_mut().zip(a) {
        *o = as_f32(x, loc, what)?;
    }
    Ok(out)
}

fn parse_track(index: usize, v: &Json) -> Result<TrackDoc, Error> {
    let mut loc = Location {
        track: Some(format!("#{index}")),
        ..Location::default()
    };
    let obj = as_object(v, &loc, "a track")?;
    let name = match obj.get("name") {
        Some(n) => as_str(n, &loc, "name")?.to_owned(),
        None => return Err(Error::invalid(loc, "missing \"name\"")),
    };
    loc.track = Some(quote(&name));
    let mut allowed = vec!["name", "kind", "times", "values", "keys"];
    allowed.extend(SettingsDoc::FIELDS);
    check_fields(obj, &allowed, &loc, "a track")?;
    let kind = match obj.get("kind") {
        Some(k) => {
            let s = as_str(k, &loc, "kind")?;
            TrackKind::from_name(s).ok_or_else(|| {
                Error::invalid(
                    loc.clone(),
                    format!(
                        "unknown kind \"{s}\" (expected one of: scalar, vec2, vec3, vec4, quat)"
                    ),
                )
            })?
        }
        None => return Err(Error::invalid(loc, "missing \"kind\"")),
    };
    let times_json = as_array(obj.get("times").unwrap_or(&Json::Null), &loc, "times")?;
    let values_json = as_array(obj.get("values").unwrap_or(&Json::Null), &loc, "values")?;
    let at = |key: usize| Location {
        key: Some(key),
        ..loc.clone()
    };
    let times = times_json
        .iter()
        .enumerate()
        .map(|(k, t)| as_f64(t, &at(k), "time"))
        .collect::<Result<Vec<_>, _>>()?;
    if values_json.len() != times.len() {
        return Err(Error::invalid(
            loc,
            format!("{} values for {} times", values_json.len(), times.len()),
        ));
    }
    let values = values_json
        .iter()
        .enumerate()
        .map(|(k, v)| parse_value(v, kind, &at(k), "value"))
        .collect::<Result<Vec<_>, _>>()?;
    let keys = match obj.get("keys") {
        None => Vec::new(),
        Some(k) => {
            let keys = as_array(k, &loc, "keys")?;
            if keys.len() != times.len() {
                return Err(Error::invalid(
                    loc,
                    format!("{} keys for {} times", keys.len(), times.len()),
                ));
            }
            keys.iter()
                .enumerate()
                .map(|(k, key)| parse_key(key, kind, &at(k)))
                .collect::<Result<Vec<_>, _>>()?
        }
    };
    let settings = parse_settings(obj, &loc)?;
    Ok(TrackDoc {
        name,
        kind,
        times,
        values,
        keys,
        settings,
    })
}

fn parse_key(v: &Json, kind: TrackKind, loc: &Location) -> Result<KeyDoc, Error> {
    let obj = as_object(v, loc, "a key")?;
    check_fields(obj, &["tcb", "ease", "interp", "in", "out"], loc, "a key")?;
    Ok(KeyDoc {
        tcb: obj.get("tcb").map(|v| parse_tcb(v, loc)).transpose()?,
        ease: obj
            .get("ease")
            .map(|v| as_numbers::<2>(v, loc, "ease"))
            .transpose()?,
        interp: obj
            .get("interp")
            .map(|v| as_enum(v, loc, "interp"))
            .transpose()?,
        tangent_in: obj
            .get("in")
            .map(|v| parse_value(v, kind, loc, "in"))
            .transpose()?,
        tangent_out: obj
            .get("out")
            .map(|v| parse_value(v, kind, loc, "out"))
            .transpose()?,
    })
}
