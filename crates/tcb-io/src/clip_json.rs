//! The clip file, format `tcb-clip/1` (the project's `docs/clip-format.md`).
//!
//! [`ClipDoc`] is the file as written: every optional field stays optional,
//! so a clip read and written again says no more than it said. [`ClipDoc::build`]
//! resolves defaults and builds the validated [`tcb_core::SourceClip`].
//!
//! Reading and writing go through serde. Parsing is strict: unknown fields
//! are errors (a misspelt `tangent_rule` would otherwise silently give
//! another curve; `deny_unknown_fields`), except `extras`, which any object
//! may carry for the user's own data, as in glTF. Errors name the track
//! and the key: serde_path_to_error says where in the document an error
//! is, and [`ClipDoc::parse`] turns that path into a [`Location`].
//!
//! A clip written reads back bit for bit: numbers are read as the nearest
//! f64 (serde_json's `float_roundtrip`) and written in their shortest
//! round-trip form, f32 values as f32 unless that form would round twice
//! to another f32 (one positive f32 does: then its f64 form).

use crate::error::{Error, ErrorKind, Location};
use crate::json::{Extras, finite_f32};
use serde::de;

use glam::{Quat, Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::Path;
use tcb_core::skeleton::Skeleton;
use tcb_core::{
    Ease, Ends, Extrapolation, Hemisphere, Interp, KeyParams, NamedTrack, RotationMode,
    RotationTrack, SourceClip, TangentRule, Tcb, Track, TrackData, TrackKind, TrackSettings, Value,
};

/// The format string a clip file carries.
pub const FORMAT: &str = "tcb-clip/1";

/// Declares a struct with the nine track settings after its own fields, so
/// that `defaults`, a track (whose overrides sit beside its own fields:
/// serde's `flatten` cannot be combined with `deny_unknown_fields`) and
/// [`SettingsDoc`] list them once.
macro_rules! with_settings {
    ($(#[$meta:meta])* $vis:vis struct $name:ident { $($body:tt)* }) => {
        $(#[$meta])*
        $vis struct $name {
            $($body)*
            /// `tangent_rule`.
            #[serde(default, skip_serializing_if = "Option::is_none", with = "named")]
            pub tangent_rule: Option<TangentRule>,
            /// `ends`.
            #[serde(default, skip_serializing_if = "Option::is_none", with = "named")]
            pub ends: Option<Ends>,
            /// `match_speed`.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub match_speed: Option<bool>,
            /// `continuity_fade`.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub continuity_fade: Option<bool>,
            /// `tcb`: the default `[t, c, b]` of keys that do not state one.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            pub tcb: Option<[f64; 3]>,
            /// `pre`.
            #[serde(default, skip_serializing_if = "Option::is_none", with = "named")]
            pub pre: Option<Extrapolation>,
            /// `post`.
            #[serde(default, skip_serializing_if = "Option::is_none", with = "named")]
            pub post: Option<Extrapolation>,
            /// `rotation` (quat tracks).
            #[serde(default, skip_serializing_if = "Option::is_none", with = "named")]
            pub rotation: Option<RotationMode>,
            /// `hemisphere` (quat tracks): `nearest` or `keep`.
            #[serde(default, skip_serializing_if = "Option::is_none", with = "named")]
            pub hemisphere: Option<Hemisphere>,
        }

        impl $name {
            /// The nine settings alone.
            #[allow(dead_code)]
            fn settings_doc(&self) -> SettingsDoc {
                SettingsDoc {
                    tangent_rule: self.tangent_rule,
                    ends: self.ends,
                    match_speed: self.match_speed,
                    continuity_fade: self.continuity_fade,
                    tcb: self.tcb,
                    pre: self.pre,
                    post: self.post,
                    rotation: self.rotation,
                    hemisphere: self.hemisphere,
                }
            }
        }
    };
}

with_settings! {
    /// Track settings as a file states them: `defaults`, or a track's overrides.
    #[derive(Clone, Debug, PartialEq, Default, Serialize)]
    pub struct SettingsDoc {}
}

impl SettingsDoc {
    /// Whether it states nothing.
    pub fn is_empty(&self) -> bool {
        *self == SettingsDoc::default()
    }

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
/// let clip = tcb_io::load_clip("examples/clips/bounce.json")?;
/// println!("{} channels", clip.channel_count());
/// # Ok::<(), tcb_io::Error>(())
/// ```
pub fn load_clip(path: impl AsRef<Path>) -> Result<SourceClip, Error> {
    let path = path.as_ref();
    let doc = read_clip_doc(path)?;
    doc.build().map_err(|e| e.in_file(path))
}

/// Read and parse the clip file at `path` without building it (files
/// above [`crate::files::DEFAULT_MAX_FILE_BYTES`] are refused unread).
pub fn read_clip_doc(path: impl AsRef<Path>) -> Result<ClipDoc, Error> {
    read_clip_doc_limited(path.as_ref(), crate::files::DEFAULT_MAX_FILE_BYTES)
}

/// [`read_clip_doc`] with its own file size limit.
pub(crate) fn read_clip_doc_limited(path: &Path, limit: u64) -> Result<ClipDoc, Error> {
    let text = crate::files::read_text_limited(path, limit)?;
    ClipDoc::parse(&text).map_err(|e| e.in_file(path))
}

/// Write `doc` to `path`: to a temporary file beside it, then renamed over
/// it, so that a failure leaves no half-written clip.
pub fn write_clip_doc(doc: &ClipDoc, path: impl AsRef<Path>) -> Result<(), Error> {
    crate::files::write_atomically(path, doc.to_json().as_bytes())
}

impl ClipDoc {
    /// Parse clip JSON. Errors carry the track and key, not the file.
    pub fn parse(text: &str) -> Result<Self, Error> {
        let mut de = serde_json::Deserializer::from_str(text);
        let file: FileIn = match serde_path_to_error::deserialize(&mut de) {
            Ok(file) => file,
            Err(e) => return Err(parse_error(text, e)),
        };
        if let Err(e) = de.end() {
            return Err(Error {
                location: Location::default(),
                kind: ErrorKind::Json {
                    line: e.line(),
                    column: e.column(),
                    message: strip_position(&e.to_string()),
                },
            });
        }
        let top = Location::default();
        if let Some(message) = format_error(file.format.map(serde_json::Value::String).as_ref()) {
            return Err(Error::invalid(top, message));
        }
        let Some(tracks) = file.tracks else {
            return Err(Error::invalid(top, "missing \"tracks\""));
        };
        Ok(ClipDoc {
            name: file.name,
            defaults: file.defaults.map(|d| d.settings_doc()).unwrap_or_default(),
            tracks: tracks
                .into_iter()
                .map(TrackIn::into_doc)
                .collect::<Result<_, _>>()?,
            skeleton: file
                .skeleton
                .map(crate::skeleton_json::SkeletonIn::into_skeleton)
                .transpose()?,
        })
    }

    /// Resolve defaults and build every track. Errors name the track and key.
    pub fn build(&self) -> Result<SourceClip, Error> {
        // A default tcb is checked even where every key states its own: a
        // clip that builds must write as it is, and JSON has no NaN.
        let tcb_error = |s: &SettingsDoc| {
            s.tcb.filter(|t| !t.iter().all(|x| x.is_finite())).map(|t| {
                let t = t.map(|x| format!("{x}"));
                format!("tcb [{}] is not finite", t.join(", "))
            })
        };
        if let Some(m) = tcb_error(&self.defaults) {
            return Err(Error::invalid(
                Location::default(),
                format!("defaults: {m}"),
            ));
        }
        let mut seen: HashMap<&str, usize> = HashMap::new();
        let mut tracks = Vec::with_capacity(self.tracks.len());
        for (i, t) in self.tracks.iter().enumerate() {
            let loc = Location {
                track: Some(quote(&t.name)),
                ..Location::default()
            };
            if let Some(m) = tcb_error(&t.settings) {
                return Err(Error::invalid(loc, m));
            }
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
        SourceClip::new(self.name.clone(), tracks).map_err(|e| {
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
    /// shortest round-trip form (f32 values and tangents as f32).
    pub fn to_json(&self) -> String {
        to_json_text(&FileOut {
            format: FORMAT,
            name: &self.name,
            defaults: &self.defaults,
            skeleton: self
                .skeleton
                .as_ref()
                .map(crate::skeleton_json::SkeletonOut::of),
            tracks: self.tracks.iter().map(TrackDoc::out).collect(),
        })
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
}

/// `Option<T>` as the name of a [`tcb_core`] enum (its `Display` and
/// `FromStr`). An unknown name's message has a `{field}` placeholder that
/// [`ClipDoc::parse`] fills with the field it was found in.
mod named {
    use serde::{Deserialize, Deserializer, Serializer, de};
    use std::fmt::Display;
    use std::str::FromStr;

    pub fn serialize<T: Display, S: Serializer>(v: &Option<T>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => s.collect_str(v),
            None => s.serialize_none(),
        }
    }

    pub fn deserialize<'de, T, D>(d: D) -> Result<Option<T>, D::Error>
    where
        T: FromStr,
        T::Err: Display,
        D: Deserializer<'de>,
    {
        let name = std::borrow::Cow::<str>::deserialize(d)?;
        name.parse()
            .map(Some)
            .map_err(|e| de::Error::custom(format!("unknown {{field}} \"{name}\" ({e})")))
    }
}

/// A value as written: a number, or an array of numbers (its shape is
/// checked against the track's kind once the kind is known).
#[derive(Clone, Debug, PartialEq)]
enum ValueIn {
    One(f64),
    /// The first 4 numbers (all a value uses) and how many there were.
    Many(Vec<f64>, usize),
}

impl<'de> Deserialize<'de> for ValueIn {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> de::Visitor<'de> for V {
            type Value = ValueIn;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of numbers")
            }
            fn visit_f64<E>(self, x: f64) -> Result<ValueIn, E> {
                Ok(ValueIn::One(x))
            }
            fn visit_i64<E>(self, x: i64) -> Result<ValueIn, E> {
                Ok(ValueIn::One(x as f64))
            }
            fn visit_u64<E>(self, x: u64) -> Result<ValueIn, E> {
                Ok(ValueIn::One(x as f64))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut a: A) -> Result<ValueIn, A::Error> {
                // At most 4 are ever used; a longer array is reported by
                // its length, without keeping what it holds.
                let (mut out, mut len) = (Vec::with_capacity(4), 0);
                while let Some(x) = a.next_element::<f64>()? {
                    if len < 4 {
                        out.push(x);
                    }
                    len += 1;
                }
                Ok(ValueIn::Many(out, len))
            }
        }
        d.deserialize_any(V)
    }
}

impl ValueIn {
    /// The value for `kind`, as f32 components padded to 4.
    fn to_value(&self, kind: TrackKind, what: &str) -> Result<[f32; 4], String> {
        let mut out = [0.0f32; 4];
        let xs: &[f64] = match (self, kind) {
            (ValueIn::One(x), TrackKind::Scalar) => std::slice::from_ref(x),
            (ValueIn::Many(..), TrackKind::Scalar) => {
                return Err(format!(
                    "{what} of a scalar track must be a number, found {}",
                    self.brief()
                ));
            }
            (ValueIn::One(_), _) => {
                return Err(format!(
                    "{what} of a {kind} track must be an array of {} numbers, found {}",
                    kind.dim(),
                    self.brief()
                ));
            }
            (ValueIn::Many(_, len), _) if *len != kind.dim() => {
                return Err(format!(
                    "{what} of a {kind} track must have {} numbers, found {}",
                    kind.dim(),
                    len
                ));
            }
            (ValueIn::Many(xs, _), _) => xs,
        };
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = finite_f32(x, what)?;
        }
        Ok(out)
    }

    fn brief(&self) -> String {
        match self {
            ValueIn::One(x) => format!("{x}"),
            ValueIn::Many(_, len) if *len > 4 => format!("an array of {len}"),
            ValueIn::Many(xs, _) => format!(
                "[{}]",
                xs.iter()
                    .map(|x| format!("{x}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }
}

/// A track's `kind`, with the contract's message for an unknown one.
fn kind<'de, D: de::Deserializer<'de>>(d: D) -> Result<TrackKind, D::Error> {
    let name = std::borrow::Cow::<str>::deserialize(d)?;
    TrackKind::from_name(&name).ok_or_else(|| {
        de::Error::custom(format!(
            "unknown {{field}} \"{name}\" (expected one of: scalar, vec2, vec3, vec4, quat)"
        ))
    })
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileIn {
    format: Option<String>,
    #[serde(default)]
    name: String,
    #[serde(default)]
    defaults: Option<DefaultsIn>,
    tracks: Option<Vec<TrackIn>>,
    #[serde(default)]
    skeleton: Option<crate::skeleton_json::SkeletonIn>,
    #[serde(default, rename = "extras")]
    _extras: Option<Extras>,
}

with_settings! {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct DefaultsIn {
        #[serde(default, rename = "extras")]
        _extras: Option<Extras>,
    }
}

with_settings! {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct TrackIn {
        name: String,
        #[serde(deserialize_with = "kind")]
        kind: TrackKind,
        times: Vec<f64>,
        values: Vec<ValueIn>,
        #[serde(default)]
        keys: Option<Vec<KeyIn>>,
        #[serde(default, rename = "extras")]
        _extras: Option<Extras>,
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyIn {
    #[serde(default)]
    tcb: Option<[f64; 3]>,
    #[serde(default)]
    ease: Option<[f64; 2]>,
    #[serde(default, with = "named")]
    interp: Option<Interp>,
    #[serde(default, rename = "in")]
    tangent_in: Option<ValueIn>,
    #[serde(default, rename = "out")]
    tangent_out: Option<ValueIn>,
    #[serde(default, rename = "extras")]
    _extras: Option<Extras>,
}

/// What an error's location needs when the strict parse fails: the
/// format, and the tracks' names (everything else skipped unread, so
/// that this pass succeeds where the strict one stopped).
#[derive(Deserialize)]
struct Outline {
    #[serde(default)]
    format: Option<serde_json::Value>,
    #[serde(default)]
    tracks: Vec<NameOnly>,
}

#[derive(Deserialize)]
struct NameOnly {
    #[serde(default)]
    name: Option<serde_json::Value>,
}

fn quote(name: &str) -> String {
    format!("'{name}'")
}

/// The format check: `None` when it is this format.
fn format_error(format: Option<&serde_json::Value>) -> Option<String> {
    match format {
        Some(serde_json::Value::String(f)) if f == FORMAT => None,
        Some(other) => Some(format!("format is {other}, expected \"{FORMAT}\"")),
        None => Some(format!("missing \"format\": \"{FORMAT}\"")),
    }
}

/// Where a serde error is, as a [`Location`] and the field it was in,
/// from its path (`tracks[3].keys[5].tcb`) and the tracks' names.
fn locate(
    path: &serde_path_to_error::Path,
    names: &[Option<String>],
) -> (Location, String, String) {
    use serde_path_to_error::Segment;
    let mut loc = Location::default();
    // The object the error is in (for messages), and the field.
    let (mut within, mut field) = ("the clip".to_owned(), String::new());
    let mut last_map: Option<&str> = None;
    for seg in path.iter() {
        match seg {
            // Inside `extras` the user's own keys say nothing to us.
            Segment::Map { key } if key == "extras" => {
                field = key.clone();
                break;
            }
            Segment::Map { key } => {
                match (last_map, key.as_str()) {
                    (None, "defaults") => within = "defaults".into(),
                    (None, "skeleton") => within = "skeleton".into(),
                    _ => {}
                }
                last_map = Some(key);
                field = key.clone();
            }
            Segment::Seq { index } => match last_map {
                Some("tracks") if loc.track.is_none() => {
                    loc.track = Some(match names.get(*index) {
                        Some(Some(n)) => quote(n),
                        _ => format!("#{index}"),
                    });
                    within = "a track".into();
                }
                Some("times" | "values" | "keys") if loc.track.is_some() => {
                    loc.key = Some(*index);
                    if last_map == Some("keys") {
                        within = "a key".into();
                    }
                }
                Some("joints") => within = format!("skeleton joint {index}"),
                _ => {}
            },
            _ => {}
        }
    }
    (loc, within, field)
}

/// The number token that ends at or near byte column `column` of `line`
/// (serde_json's position of a number it refused), if it is one.
fn number_at(text: &str, line: usize, column: usize) -> Option<&str> {
    let start_of_line: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    let at = (start_of_line + column).min(text.len());
    let is_num = |c: u8| c.is_ascii_digit() || matches!(c, b'e' | b'E' | b'+' | b'-' | b'.');
    let bytes = text.as_bytes();
    let mut end = at;
    while end > start_of_line && !is_num(bytes[end - 1]) {
        end -= 1;
    }
    while end < bytes.len() && is_num(bytes[end]) {
        end += 1;
    }
    let mut start = end;
    while start > 0 && is_num(bytes[start - 1]) {
        start -= 1;
    }
    let token = &text[start..end];
    token.parse::<f64>().ok().map(|_| token)
}

/// The error for a failed strict parse.
fn parse_error(text: &str, e: serde_path_to_error::Error<serde_json::Error>) -> Error {
    let outline: Option<Outline> = serde_json::from_str(text).ok();
    if let Some(o) = &outline
        && let Some(message) = format_error(o.format.as_ref())
    {
        return Error::invalid(Location::default(), message);
    }
    let names: Vec<Option<String>> = outline.map_or_else(Vec::new, |o| {
        o.tracks
            .into_iter()
            .map(|t| t.name.and_then(|n| n.as_str().map(str::to_owned)))
            .collect()
    });
    let (mut location, within, field) = locate(e.path(), &names);
    // One entry of `times` or `values` is one key's time or value.
    let field = match field.as_str() {
        "times" => "time".to_owned(),
        "values" => "value".to_owned(),
        _ => field,
    };
    // Inside a track the location says where; elsewhere the message does.
    let prefix = match (&location.track, within.as_str()) {
        (None, w) if w != "the clip" => format!("{w}: "),
        _ => String::new(),
    };
    let inner = e.into_inner();
    let (line, column) = (inner.line(), inner.column());
    let message = strip_position(&inner.to_string())
        .replace('`', "\"")
        .replace("expected f64", "expected a number")
        .replace(
            "recursion limit exceeded",
            "nested deeper than 128 levels (the JSON reader's limit)",
        );
    if inner.is_syntax() || inner.is_eof() {
        // JSON has no infinity: a number beyond f64 (1e999) is refused by
        // the tokenizer; say which, where the track and key are known.
        if let Some(token) = number_at(text, line, column)
            && token.parse::<f64>().is_ok_and(f64::is_infinite)
        {
            return Error::invalid(
                location,
                format!("{prefix}{field} {token} is not a finite number"),
            );
        }
        // Broken JSON: its line and column say where.
        location = Location::default();
        return Error {
            location,
            kind: ErrorKind::Json {
                line,
                column,
                message,
            },
        };
    }
    let message = if message.contains("{field}") {
        message.replacen("{field}", &field, 1)
    } else if message.starts_with("unknown field")
        || message.starts_with("missing field")
        || field.is_empty()
    {
        message
    } else {
        format!("{field}: {message}")
    };
    Error::invalid(location, format!("{prefix}{message}"))
}

/// serde_json appends " at line L column C"; we report those separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_owned(),
        None => message.to_owned(),
    }
}

impl TrackIn {
    fn into_doc(self) -> Result<TrackDoc, Error> {
        let loc = Location {
            track: Some(quote(&self.name)),
            ..Location::default()
        };
        let at = |key: usize| Location {
            key: Some(key),
            ..loc.clone()
        };
        if self.values.len() != self.times.len() {
            return Err(Error::invalid(
                loc,
                format!(
                    "{} values for {} times",
                    self.values.len(),
                    self.times.len()
                ),
            ));
        }
        let values = self
            .values
            .iter()
            .enumerate()
            .map(|(k, v)| {
                v.to_value(self.kind, "value")
                    .map_err(|m| Error::invalid(at(k), m))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let keys = match &self.keys {
            None => Vec::new(),
            Some(keys) if keys.len() != self.times.len() => {
                return Err(Error::invalid(
                    loc,
                    format!("{} keys for {} times", keys.len(), self.times.len()),
                ));
            }
            Some(keys) => keys
                .iter()
                .enumerate()
                .map(|(k, key)| {
                    let value = |v: &Option<ValueIn>, what| {
                        v.as_ref()
                            .map(|v| v.to_value(self.kind, what))
                            .transpose()
                            .map_err(|m| Error::invalid(at(k), m))
                    };
                    Ok(KeyDoc {
                        tcb: key.tcb,
                        ease: key.ease,
                        interp: key.interp,
                        tangent_in: value(&key.tangent_in, "in")?,
                        tangent_out: value(&key.tangent_out, "out")?,
                    })
                })
                .collect::<Result<Vec<_>, Error>>()?,
        };
        Ok(TrackDoc {
            settings: self.settings_doc(),
            name: self.name,
            kind: self.kind,
            times: self.times,
            values,
            keys,
        })
    }
}

/// Lays a clip out one line per field of a track, so that large clips stay
/// readable and diffable: containers down to the tracks' fields are
/// indented, anything inside a field (times, values, keys) is on one line.
#[derive(Default)]
struct ClipFormatter {
    depth: usize,
    has_value: bool,
    /// A number's text, before it is written.
    number: Vec<u8>,
}

impl ClipFormatter {
    /// Containers this deep or less put each entry on its own line.
    const PRETTY: usize = 3;

    fn entry<W: ?Sized + std::io::Write>(&self, w: &mut W, first: bool) -> std::io::Result<()> {
        if self.depth <= Self::PRETTY {
            w.write_all(if first { b"\n" } else { b",\n" })?;
            w.write_all(&b" ".repeat(2 * self.depth))
        } else if first {
            Ok(())
        } else {
            w.write_all(b", ")
        }
    }

    fn open<W: ?Sized + std::io::Write>(&mut self, w: &mut W, c: &[u8]) -> std::io::Result<()> {
        self.depth += 1;
        self.has_value = false;
        w.write_all(c)
    }

    fn close<W: ?Sized + std::io::Write>(&mut self, w: &mut W, c: &[u8]) -> std::io::Result<()> {
        if self.depth <= Self::PRETTY && self.has_value {
            w.write_all(b"\n")?;
            w.write_all(&b" ".repeat(2 * (self.depth - 1)))?;
        }
        self.depth -= 1;
        w.write_all(c)
    }
}

impl serde_json::ser::Formatter for ClipFormatter {
    fn begin_array<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.open(w, b"[")
    }
    fn end_array<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.close(w, b"]")
    }
    fn begin_array_value<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        self.entry(w, first)
    }
    fn end_array_value<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        self.has_value = true;
        Ok(())
    }
    fn begin_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.open(w, b"{")
    }
    fn end_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.close(w, b"}")
    }
    fn begin_object_key<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        self.entry(w, first)
    }
    fn begin_object_value<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        w.write_all(b": ")
    }
    fn end_object_value<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        self.has_value = true;
        Ok(())
    }
    fn write_f32<W: ?Sized + std::io::Write>(&mut self, w: &mut W, x: f32) -> std::io::Result<()> {
        self.number.clear();
        serde_json::ser::CompactFormatter.write_f32(&mut self.number, x)?;
        if !reads_back_as_f32(&self.number, x) {
            // The reader takes a number as the nearest f64, then rounds
            // it to f32: that rounds twice, and for one f32 in 2^31
            // (`7.038531e-26`, found by trying every f32) the shortest
            // decimal lands on the midpoint of two f32s and rounds to the
            // other. The f32's own value, written as an f64, is exact.
            self.number.clear();
            serde_json::ser::CompactFormatter.write_f64(&mut self.number, f64::from(x))?;
        }
        self.write_number(w)
    }
    fn write_f64<W: ?Sized + std::io::Write>(&mut self, w: &mut W, x: f64) -> std::io::Result<()> {
        self.number.clear();
        serde_json::ser::CompactFormatter.write_f64(&mut self.number, x)?;
        self.write_number(w)
    }
}

/// Whether `text`, read as the clip reader reads an f32 (the nearest f64,
/// then rounded to f32), gives `x` back bit for bit.
fn reads_back_as_f32(text: &[u8], x: f32) -> bool {
    std::str::from_utf8(text)
        .ok()
        .and_then(|t| t.parse::<f64>().ok())
        .is_some_and(|y| (y as f32).to_bits() == x.to_bits())
}

impl ClipFormatter {
    /// serde_json's shortest round-trip form, without the `.0` of whole
    /// numbers (motion capture is full of them) or the `+` of exponents.
    fn write_number<W: ?Sized + std::io::Write>(&self, w: &mut W) -> std::io::Result<()> {
        let n = self.number.as_slice();
        let n = n.strip_suffix(b".0").unwrap_or(n);
        match n.windows(2).position(|p| p == b"e+") {
            Some(i) => {
                w.write_all(&n[..=i])?;
                w.write_all(&n[i + 2..])
            }
            None => w.write_all(n),
        }
    }
}

#[derive(Serialize)]
struct FileOut<'a> {
    format: &'static str,
    name: &'a str,
    #[serde(skip_serializing_if = "SettingsDoc::is_empty")]
    defaults: &'a SettingsDoc,
    #[serde(skip_serializing_if = "Option::is_none")]
    skeleton: Option<crate::skeleton_json::SkeletonOut<'a>>,
    tracks: Vec<TrackOut<'a>>,
}

#[derive(Serialize)]
struct TrackOut<'a> {
    name: &'a str,
    #[serde(serialize_with = "display")]
    kind: TrackKind,
    times: &'a [f64],
    values: Vec<ValueOut<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    keys: Option<Vec<KeyOut<'a>>>,
    #[serde(flatten)]
    settings: &'a SettingsDoc,
}

#[derive(Serialize)]
struct KeyOut<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    tcb: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ease: Option<[f64; 2]>,
    #[serde(skip_serializing_if = "Option::is_none", with = "named")]
    interp: Option<Interp>,
    #[serde(rename = "in", skip_serializing_if = "Option::is_none")]
    tangent_in: Option<ValueOut<'a>>,
    #[serde(rename = "out", skip_serializing_if = "Option::is_none")]
    tangent_out: Option<ValueOut<'a>>,
}

/// A value of a track's kind: a number for scalars, else its components.
struct ValueOut<'a>(&'a [f32]);

impl<'a> ValueOut<'a> {
    fn of(kind: TrackKind, v: &'a [f32; 4]) -> Self {
        ValueOut(&v[..kind.dim()])
    }
}

impl Serialize for ValueOut<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0 {
            [x] => s.serialize_f32(*x),
            xs => xs.serialize(s),
        }
    }
}

fn display<T: std::fmt::Display, S: serde::Serializer>(v: &T, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(v)
}

impl TrackDoc {
    fn out(&self) -> TrackOut<'_> {
        let kind = self.kind;
        fn value(kind: TrackKind, v: &Option<[f32; 4]>) -> Option<ValueOut<'_>> {
            v.as_ref().map(|v| ValueOut::of(kind, v))
        }
        TrackOut {
            name: &self.name,
            kind,
            times: &self.times,
            values: self.values.iter().map(|v| ValueOut::of(kind, v)).collect(),
            keys: self.keys.iter().any(|k| !k.is_empty()).then(|| {
                self.keys
                    .iter()
                    .map(|k| KeyOut {
                        tcb: k.tcb,
                        ease: k.ease,
                        interp: k.interp,
                        tangent_in: value(kind, &k.tangent_in),
                        tangent_out: value(kind, &k.tangent_out),
                    })
                    .collect()
            }),
            settings: &self.settings,
        }
    }
}

/// `value` as JSON in the clip file's layout ([`ClipFormatter`]).
pub(crate) fn to_json_text<T: Serialize>(value: &T) -> String {
    let mut buf = Vec::new();
    let mut ser = serde_json::Serializer::with_formatter(&mut buf, ClipFormatter::default());
    // Writing to memory fails only if a Serialize impl refuses, and ours
    // do not (non-finite numbers are written as null, as serde_json does).
    if value.serialize(&mut ser).is_err() {
        buf.clear();
    }
    buf.push(b'\n');
    String::from_utf8(buf).unwrap_or_default()
}
