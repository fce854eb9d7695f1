//! glTF 2.0 animations (`.gltf` with external or data-URI buffers, `.glb`).
//!
//! Buffers are resolved here rather than by the `gltf` crate's `import`
//! feature (which would pull in image decoding), and every accessor is
//! checked against the bytes that exist before anything is read or
//! allocated, so a file claiming more than it holds is an error, not a panic
//! or a huge allocation.

use crate::clip_json::{ClipDoc, KeyDoc, SettingsDoc, TrackDoc};
use crate::error::Error;
use glam::{Quat, Vec3};
use gltf::Document;
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::{Interpolation, Property};
use std::path::Path;
use tcb_core::skeleton::{Joint, Skeleton, Transform};
use tcb_core::{Hemisphere, Interp, RotationMode, TrackKind};

/// A glTF file's hierarchy and one of its animations as a clip.
#[derive(Clone, Debug)]
pub struct GltfImport {
    /// The animation as a clip document.
    pub doc: ClipDoc,
    /// Every node reachable from a root, parents first, with its rest
    /// transform; joint names are the track name prefixes.
    pub skeleton: Skeleton,
    /// Things that were read but look odd.
    pub warnings: Vec<String>,
}

/// Refuse indices the `gltf` crate (1.4.1) reads unchecked and panics on,
/// its own validation included (both found by the `gltf` fuzz target): a
/// mesh primitive's `POSITION` accessor (`primitive_validate_hook`), an
/// animation channel's target node and sampler and a sampler's accessors
/// (`Channel::target().node()` unwraps), and a target path or an
/// interpolation it could not read (`Target::property()` unwraps).
fn check_indices(root: &gltf::json::Root) -> Result<(), Error> {
    use gltf::json::validation::Checked;
    let bad = |what: String, index: usize, kind: &str, count: usize| {
        Error::import(format!(
            "not a valid glTF 2.0 file: {what} is {kind} {index}, but the file has {count} {kind}s"
        ))
    };
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            let position = Checked::Valid(gltf::json::mesh::Semantic::Positions);
            if let Some(a) = primitive.attributes.get(&position)
                && a.value() >= root.accessors.len()
            {
                let what = format!("meshes[{m}].primitives[{p}].attributes.POSITION");
                return Err(bad(what, a.value(), "accessor", root.accessors.len()));
            }
        }
    }
    for (a, anim) in root.animations.iter().enumerate() {
        for (c, channel) in anim.channels.iter().enumerate() {
            let node = channel.target.node.value();
            if node >= root.nodes.len() {
                let what = format!("animations[{a}].channels[{c}].target.node");
                return Err(bad(what, node, "node", root.nodes.len()));
            }
            if !matches!(channel.target.path, Checked::Valid(_)) {
                return Err(Error::import(format!(
                    "not a valid glTF 2.0 file: animations[{a}].channels[{c}].target.path is not translation, rotation, scale or weights"
                )));
            }
            let sampler = channel.sampler.value();
            if sampler >= anim.samplers.len() {
                let what = format!("animations[{a}].channels[{c}].sampler");
                return Err(bad(what, sampler, "sampler", anim.samplers.len()));
            }
        }
        for (i, sampler) in anim.samplers.iter().enumerate() {
            if !matches!(sampler.interpolation, Checked::Valid(_)) {
                return Err(Error::import(format!(
                    "not a valid glTF 2.0 file: animations[{a}].samplers[{i}].interpolation is not LINEAR, STEP or CUBICSPLINE"
                )));
            }
            for (field, acc) in [("input", sampler.input), ("output", sampler.output)] {
                if acc.value() >= root.accessors.len() {
                    let what = format!("animations[{a}].samplers[{i}].{field}");
                    return Err(bad(what, acc.value(), "accessor", root.accessors.len()));
                }
            }
        }
    }
    Ok(())
}

/// Import animation `animation` (a name or an index; the first when `None`)
/// from glTF or GLB bytes. `base` is the directory external buffers are
/// relative to (`None`: external buffers are an error; an `Option<&Path>`
/// rather than a generic path, so that `None` needs no type).
pub fn import(
    bytes: &[u8],
    base: Option<&Path>,
    animation: Option<&str>,
    name: &str,
) -> Result<GltfImport, Error> {
    let options = crate::files::ImportOptions {
        animation: animation.map(str::to_string),
        ..Default::default()
    };
    import_with(bytes, base, name, &options)
}

/// [`import`] with the animation, the file size limit and the buffer URI
/// policy of `options`: a buffer URI is a `data:` URI or a relative path
/// that stays inside `base`, unless `options.allow_outside_paths`.
pub fn import_with(
    bytes: &[u8],
    base: Option<&Path>,
    name: &str,
    options: &crate::files::ImportOptions,
) -> Result<GltfImport, Error> {
    let gltf = parse(bytes)?;
    let buffers = load_buffers(&gltf.document, gltf.blob.as_deref(), base, options)?;
    let mut warnings = Vec::new();
    let names = node_names(&gltf.document, &mut warnings);
    let skeleton = skeleton(&gltf.document, &names);
    let anim = choose_animation(&gltf.document, options.animation.as_deref(), &mut warnings)?;
    let mut tracks = Vec::new();
    for (c, channel) in anim.channels().enumerate() {
        let node = &names[channel.target().node().index()];
        channel_tracks(&buffers, &channel, node, &mut tracks, &mut warnings).map_err(|m| {
            Error::import(format!(
                "animation {}, channel {c} ({node}): {m}",
                describe(&anim)
            ))
        })?;
    }
    Ok(GltfImport {
        doc: ClipDoc {
            name: anim.name().unwrap_or(name).to_string(),
            defaults: SettingsDoc::default(),
            tracks,
            skeleton: Some(skeleton.clone()),
        },
        skeleton,
        warnings,
    })
}

/// A glTF or GLB file's document, its indices checked before the `gltf`
/// crate follows them.
fn parse(bytes: &[u8]) -> Result<gltf::Gltf, Error> {
    let invalid =
        |e: &dyn std::fmt::Display| Error::import(format!("not a valid glTF 2.0 file: {e}"));
    // Neither the GLB magic nor a JSON object first (white space and a
    // byte-order mark skipped, so that JSON gets the parser's own words):
    // say so, not serde_json's "expected value at line 1 column 1".
    let json = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if !bytes.starts_with(b"glTF") && !json.trim_ascii_start().starts_with(b"{") {
        return Err(Error::import(
            "not a glTF file: neither binary glTF (no \"glTF\" magic) nor glTF JSON (no '{' first)",
        ));
    }
    // The `gltf` crate (1.4.1) subtracts the header's 12 bytes from the
    // GLB length field before it checks it (an overflow, a panic in debug
    // builds): check it here first.
    if let Some(length) = bytes
        .strip_prefix(b"glTF")
        .and_then(|rest| rest.get(4..8))
        .map(|l| u32::from_le_bytes([l[0], l[1], l[2], l[3]]))
        && length < 12
    {
        return Err(invalid(&format!(
            "the GLB header says the file is {length} bytes, less than its own 12-byte header"
        )));
    }
    let unchecked = gltf::Gltf::from_slice_without_validation(bytes).map_err(|e| invalid(&e))?;
    let json = unchecked.document.into_json();
    check_indices(&json)?;
    Ok(gltf::Gltf {
        document: gltf::Document::from_json(json).map_err(|e| invalid(&e))?,
        blob: unchecked.blob,
    })
}

/// The animation `want` names (by name, else by index), or the first
/// (with a warning when there are others).
fn choose_animation<'a>(
    document: &'a Document,
    want: Option<&str>,
    warnings: &mut Vec<String>,
) -> Result<gltf::Animation<'a>, Error> {
    let animations: Vec<_> = document.animations().collect();
    if animations.is_empty() {
        return Err(Error::import("the file has no animations"));
    }
    match want {
        None => {
            if animations.len() > 1 {
                warnings.push(format!(
                    "{} animations; imported the first ({}); choose with --animation NAME_OR_INDEX",
                    animations.len(),
                    describe(&animations[0])
                ));
            }
            Ok(animations[0].clone())
        }
        Some(want) => animations
            .iter()
            .find(|a| a.name() == Some(want))
            .or_else(|| want.parse::<usize>().ok().and_then(|i| animations.get(i)))
            .cloned()
            .ok_or_else(|| {
                let all: Vec<String> = animations.iter().map(describe).collect();
                Error::import(format!(
                    "no animation '{want}' (the file has: {})",
                    all.join(", ")
                ))
            }),
    }
}

/// The track name suffix, kind and components of a channel's target.
fn target_kind(property: Property) -> (&'static str, TrackKind, usize) {
    match property {
        Property::Translation => ("translation", TrackKind::Vec3, 3),
        Property::Rotation => ("rotation", TrackKind::Quat, 4),
        Property::Scale => ("scale", TrackKind::Vec3, 3),
        Property::MorphTargetWeights => ("weights", TrackKind::Scalar, 1),
    }
}

/// The tracks of one animation channel of node `node` (one per morph
/// target for weights), appended to `tracks`; the error says what, not
/// where.
fn channel_tracks(
    buffers: &[Vec<u8>],
    channel: &gltf::animation::Channel,
    node: &str,
    tracks: &mut Vec<TrackDoc>,
    warnings: &mut Vec<String>,
) -> Result<(), String> {
    let sampler = channel.sampler();
    let times: Vec<f64> = read(buffers, &sampler.input(), 1)
        .map_err(|m| format!("input: {m}"))?
        .into_iter()
        .map(f64::from)
        .collect();
    let interp = sampler.interpolation();
    let per_key = if interp == Interpolation::CubicSpline {
        3
    } else {
        1
    };
    let (suffix, kind, dim) = target_kind(channel.target().property());
    let out = read(buffers, &sampler.output(), dim).map_err(|m| format!("output: {m}"))?;
    let rows = out.len() / dim;
    let elements = times.len() * per_key;
    if elements == 0 || rows % elements != 0 || (dim > 1 && rows != elements) {
        return Err(format!(
            "{} input times but {rows} output elements (expected {} per key{})",
            times.len(),
            per_key,
            if dim == 1 { " per morph target" } else { "" }
        ));
    }
    let targets = rows / elements;
    for target_index in 0..targets {
        // Element e of key k, morph target i: row (k * per_key + e) * targets + i.
        let value = |k: usize, e: usize| -> [f32; 4] {
            let row = (k * per_key + e) * targets + target_index;
            let mut v = [0.0; 4];
            v[..dim].copy_from_slice(&out[row * dim..(row + 1) * dim]);
            v
        };
        let name = if kind == TrackKind::Scalar {
            format!("{node}.weights.{target_index}")
        } else {
            format!("{node}.{suffix}")
        };
        if tracks.iter().any(|t: &TrackDoc| t.name == name) {
            return Err(format!("a second channel animates '{name}'"));
        }
        let mut track = sampler_track(name, kind, times.clone(), interp, value);
        if track.times.len() == 1 {
            hold_single_key(&mut track);
            warnings.push(format!(
                "{node}.{suffix}: one key; held as a constant (second key at {} s)",
                track.times[1]
            ));
        }
        tracks.push(track);
    }
    Ok(())
}

/// A track of one key made a constant: a clip track needs two keys, so a
/// second one 1 s later, the first a `step`.
fn hold_single_key(track: &mut TrackDoc) {
    track.times.push(track.times[0] + 1.0);
    track.values.push(track.values[0]);
    track.keys.push(track.keys[0].clone());
    track.keys[0].interp = Some(Interp::Step);
}

/// One glTF sampler's keys as a clip track, as `tcb import` reads them:
/// `value(k, e)` is element `e` of key `k` (CUBICSPLINE: 0 in-tangent, 1
/// value, 2 out-tangent; otherwise 0 the value). `LINEAR` and `STEP` become
/// `interp` keys, `CUBICSPLINE` explicit tangents (rotations `hermite`,
/// `keep`, as viewers interpolate the stored components, clip-format.md).
/// The glTF export reads its own samplers back through this.
pub(crate) fn sampler_track(
    name: String,
    kind: TrackKind,
    times: Vec<f64>,
    interp: Interpolation,
    value: impl Fn(usize, usize) -> [f32; 4],
) -> TrackDoc {
    let value_e = if interp == Interpolation::CubicSpline {
        1
    } else {
        0
    };
    let values = (0..times.len()).map(|k| value(k, value_e)).collect();
    let keys = (0..times.len())
        .map(|k| match interp {
            Interpolation::Linear => KeyDoc {
                interp: Some(Interp::Linear),
                ..KeyDoc::default()
            },
            Interpolation::Step => KeyDoc {
                interp: Some(Interp::Step),
                ..KeyDoc::default()
            },
            Interpolation::CubicSpline => KeyDoc {
                tangent_in: Some(value(k, 0)),
                tangent_out: Some(value(k, 2)),
                ..KeyDoc::default()
            },
        })
        .collect();
    let mut settings = SettingsDoc::default();
    if kind == TrackKind::Quat && interp == Interpolation::CubicSpline {
        settings.rotation = Some(RotationMode::Hermite);
        settings.hemisphere = Some(Hemisphere::Keep);
    }
    TrackDoc {
        name,
        kind,
        times,
        values,
        keys,
        settings,
    }
}

/// An animation as messages name it: `'name' (index)` or its index.
fn describe(a: &gltf::Animation) -> String {
    match a.name() {
        Some(n) => format!("'{n}' ({})", a.index()),
        None => format!("{}", a.index()),
    }
}

/// `<node name>`, or `node<index>` for an unnamed node or a repeated name.
fn node_names(doc: &Document, warnings: &mut Vec<String>) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for node in doc.nodes() {
        let fallback = format!("node{}", node.index());
        let name = match node.name() {
            Some(n) if !n.is_empty() && !names.iter().any(|m| m == n) => n.to_string(),
            Some(n) if !n.is_empty() => {
                warnings.push(format!(
                    "node {} repeats the name '{n}'; its tracks are named '{fallback}'",
                    node.index()
                ));
                fallback
            }
            _ => fallback,
        };
        names.push(name);
    }
    names
}

/// The node hierarchy as a skeleton, parents before children (breadth first from the roots).
fn skeleton(doc: &Document, names: &[String]) -> Skeleton {
    let n = doc.nodes().len();
    let mut parent = vec![None; n];
    for node in doc.nodes() {
        for child in node.children() {
            if parent[child.index()].is_none() && child.index() != node.index() {
                parent[child.index()] = Some(node.index());
            }
        }
    }
    // Breadth first from the roots: parents before children; nodes on a
    // cycle are never reached and left out.
    let mut order: Vec<usize> = (0..n).filter(|&i| parent[i].is_none()).collect();
    let mut seen = vec![false; n];
    for &i in &order {
        seen[i] = true;
    }
    let mut at = 0;
    while at < order.len() {
        let node = doc.nodes().nth(order[at]).expect("index from the document");
        for child in node.children() {
            if !seen[child.index()] && parent[child.index()] == Some(node.index()) {
                seen[child.index()] = true;
                order.push(child.index());
            }
        }
        at += 1;
    }
    let mut slot = vec![usize::MAX; n];
    for (j, &i) in order.iter().enumerate() {
        slot[i] = j;
    }
    let joints = order
        .iter()
        .map(|&i| {
            let node = doc.nodes().nth(i).expect("index from the document");
            let (t, r, s) = node.transform().decomposed();
            Joint {
                name: names[i].clone(),
                parent: parent[i].map(|p| slot[p]),
                rest: Transform {
                    translation: Vec3::from_array(t),
                    // A zero rotation is left as it is: the reader refuses it.
                    rotation: match Quat::from_array(r) {
                        q if q.length_squared() == 0.0 => q,
                        q => crate::skeleton_json::unit_rotation(q),
                    },
                    scale: Vec3::from_array(s),
                },
            }
        })
        .collect();
    Skeleton::new(joints).expect("breadth first from the roots: parents before children")
}

/// Every buffer's bytes: the GLB chunk, a data URI or an external file (`read_buffer`), checked against its `byteLength`.
fn load_buffers(
    doc: &Document,
    blob: Option<&[u8]>,
    base: Option<&Path>,
    options: &crate::files::ImportOptions,
) -> Result<Vec<Vec<u8>>, Error> {
    doc.buffers()
        .map(|b| {
            let i = b.index();
            let data = match b.source() {
                gltf::buffer::Source::Bin => blob
                    .ok_or_else(|| {
                        Error::import(format!(
                            "buffer {i}: refers to the GLB binary chunk, which is missing"
                        ))
                    })?
                    .to_vec(),
                gltf::buffer::Source::Uri(uri) => {
                    if let Some(rest) = uri.strip_prefix("data:") {
                        let (head, payload) = rest.split_once(',').ok_or_else(|| {
                            Error::import(format!("buffer {i}: malformed data URI"))
                        })?;
                        if !head.ends_with(";base64") {
                            return Err(Error::import(format!(
                                "buffer {i}: only base64 data URIs are supported"
                            )));
                        }
                        base64_decode(payload)
                            .map_err(|m| Error::import(format!("buffer {i}: {m}")))?
                    } else {
                        let base = base.ok_or_else(|| {
                            Error::import(format!(
                                "buffer {i}: external file '{uri}' but no directory to find it in"
                            ))
                        })?;
                        read_buffer(base, uri, b.length(), options)
                            .map_err(|m| Error::import(format!("buffer {i} ('{uri}'): {m}")))?
                    }
                }
            };
            if data.len() < b.length() {
                return Err(Error::import(format!(
                    "buffer {i}: {} bytes, but the file says {}",
                    data.len(),
                    b.length()
                )));
            }
            Ok(data)
        })
        .collect()
}

/// The bytes of an external buffer: `uri` (percent-decoded) relative to
/// `base`, refused when it leaves `base` (an absolute path, `..`, a
/// symbolic link out of it) unless `options.allow_outside_paths`, or when it
/// is not a regular file; its size is checked against `byte_length` before
/// anything is allocated, and only `byte_length` bytes are read.
fn read_buffer(
    base: &Path,
    uri: &str,
    byte_length: usize,
    options: &crate::files::ImportOptions,
) -> Result<Vec<u8>, String> {
    use std::io::Read;
    use std::path::Component;
    let base = if base.as_os_str().is_empty() {
        Path::new(".")
    } else {
        base
    };
    let decoded = percent_decode(uri);
    let relative = Path::new(&decoded);
    let outside = "is outside the glTF file's folder (allow it with --allow-outside-paths for a trusted asset tree)";
    let climbs = relative.components().any(|c| {
        matches!(
            c,
            Component::ParentDir | Component::RootDir | Component::Prefix(_)
        )
    });
    if !options.allow_outside_paths && (climbs || relative.is_absolute() || decoded.contains('\\'))
    {
        return Err(outside.into());
    }
    let path = base.join(relative);
    let meta = std::fs::metadata(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    if !options.allow_outside_paths {
        // Through symbolic links too: the real file must be under the real folder.
        let real = std::fs::canonicalize(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let folder = std::fs::canonicalize(base).map_err(|e| format!("{}: {e}", base.display()))?;
        if !real.starts_with(&folder) {
            return Err(format!("{outside}: it resolves to {}", real.display()));
        }
    }
    if !meta.is_file() {
        return Err(format!("{} is not a regular file", path.display()));
    }
    let want = byte_length as u64;
    if want > options.max_file_bytes {
        return Err(format!(
            "byteLength {want} is above the {} bytes allowed (ImportOptions::max_file_bytes)",
            options.max_file_bytes
        ));
    }
    if meta.len() < want {
        return Err(format!(
            "{} has {} bytes but the buffer's byteLength is {want}",
            path.display(),
            meta.len()
        ));
    }
    let file = std::fs::File::open(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut bytes = Vec::with_capacity(byte_length);
    file.take(want)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(bytes)
}

/// Read accessor `a` as f32 rows of `dim` components (normalized integers
/// converted as the glTF spec says), after checking that every byte it
/// names exists.
fn read(buffers: &[Vec<u8>], a: &gltf::Accessor, dim: usize) -> Result<Vec<f32>, String> {
    let want = match dim {
        1 => Dimensions::Scalar,
        3 => Dimensions::Vec3,
        _ => Dimensions::Vec4,
    };
    if a.dimensions() != want {
        return Err(format!(
            "accessor {} is {:?}, expected {want:?}",
            a.index(),
            a.dimensions()
        ));
    }
    let ty = a.data_type();
    let float = ty == DataType::F32;
    if !float && !a.normalized() {
        return Err(format!(
            "accessor {} is {ty:?} and not normalized (expected floats)",
            a.index()
        ));
    }
    if ty == DataType::U32 {
        return Err(format!(
            "accessor {} is u32 (not allowed for animation)",
            a.index()
        ));
    }
    let count = a.count();
    if count == 0 {
        return Err(format!("accessor {} has no elements", a.index()));
    }
    let what = format!("accessor {}", a.index());
    let mut out = match a.view() {
        Some(view) => decode(buffers, &view, a.offset(), count, ty, dim, true, &what)?,
        // A sparse accessor without a view starts from zeros; bound what
        // that allocates (a count is a u32 in the file, not in its bytes).
        None if a.sparse().is_some() => {
            if count > MAX_SPARSE_ELEMENTS {
                return Err(format!(
                    "{what}: sparse over {count} elements with no buffer view (at most {MAX_SPARSE_ELEMENTS})"
                ));
            }
            vec![0.0; count * dim]
        }
        None => return Err(format!("{what} has no buffer view")),
    };
    if let Some(sparse) = a.sparse() {
        apply_sparse(buffers, &sparse, &mut out, ty, dim, &what)?;
    }
    Ok(out)
}

/// Core glTF 2.0 sparse storage (gltf-transform writes it for morph
/// animation): replaces the listed elements of `out` (`dim` components
/// each), after checking every index and byte.
fn apply_sparse(
    buffers: &[Vec<u8>],
    sparse: &gltf::accessor::sparse::Sparse,
    out: &mut [f32],
    ty: DataType,
    dim: usize,
    what: &str,
) -> Result<(), String> {
    let count = out.len() / dim;
    let n = sparse.count();
    if n == 0 || n > count {
        return Err(format!(
            "{what}: sparse count {n} (must be 1 to the accessor's {count})"
        ));
    }
    let iv = sparse.indices();
    let size = iv.index_type().size();
    let raw = bytes_of(buffers, &iv.view(), iv.offset(), n * size).ok_or_else(|| {
        format!(
            "{what}: {n} sparse indices do not fit in buffer view {}",
            iv.view().index()
        )
    })?;
    let vv = sparse.values();
    let values = decode(buffers, &vv.view(), vv.offset(), n, ty, dim, false, what)?;
    let mut previous = None;
    for (i, b) in raw.chunks_exact(size).enumerate() {
        let index = match size {
            1 => usize::from(b[0]),
            2 => usize::from(u16::from_le_bytes([b[0], b[1]])),
            _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
        };
        if index >= count || previous.is_some_and(|p| index <= p) {
            return Err(format!(
                "{what}: sparse index {i} is {index} (indices must increase and stay below {count})"
            ));
        }
        previous = Some(index);
        out[index * dim..(index + 1) * dim].copy_from_slice(&values[i * dim..(i + 1) * dim]);
    }
    Ok(())
}

/// Largest element count of a sparse accessor with no buffer view.
const MAX_SPARSE_ELEMENTS: usize = 1 << 24;

/// `len` bytes at `offset` in `view`, if they are there.
fn bytes_of<'a>(
    buffers: &'a [Vec<u8>],
    view: &gltf::buffer::View,
    offset: usize,
    len: usize,
) -> Option<&'a [u8]> {
    let data = buffers.get(view.buffer().index())?;
    let end = offset.checked_add(len)?;
    let view_end = view.offset().checked_add(view.length())?;
    (end <= view.length() && view_end <= data.len())
        .then(|| &data[view.offset() + offset..view.offset() + end])
}

/// `count` elements of `dim` components of type `ty` (normalized integers
/// converted as the glTF spec says) from `offset` in `view`, after checking
/// that every byte exists. Sparse values are tightly packed (`strided`
/// false).
#[allow(clippy::too_many_arguments)]
fn decode(
    buffers: &[Vec<u8>],
    view: &gltf::buffer::View,
    offset: usize,
    count: usize,
    ty: DataType,
    dim: usize,
    strided: bool,
    what: &str,
) -> Result<Vec<f32>, String> {
    let size = ty.size();
    let elem = size * dim;
    let stride = if strided {
        view.stride().unwrap_or(elem)
    } else {
        elem
    };
    let span = (|| count.checked_sub(1)?.checked_mul(stride)?.checked_add(elem))();
    let bytes = span
        .filter(|_| stride >= elem)
        .and_then(|len| bytes_of(buffers, view, offset, len))
        .ok_or_else(|| {
            format!(
                "{what}: {count} elements of {elem} bytes (stride {stride}) from byte {offset} do not fit in buffer view {} ({} bytes) or its buffer",
                view.index(),
                view.length()
            )
        })?;
    let mut out = Vec::with_capacity(count * dim);
    for e in 0..count {
        for c in 0..dim {
            let at = e * stride + c * size;
            let b = &bytes[at..at + size];
            let v = match ty {
                DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                DataType::I8 => (f32::from(b[0] as i8) / 127.0).max(-1.0),
                DataType::U8 => f32::from(b[0]) / 255.0,
                DataType::I16 => (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0),
                DataType::U16 => f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
                DataType::U32 => return Err(format!("{what} is u32 (not allowed for animation)")),
            };
            if !v.is_finite() {
                return Err(format!("{what}: element {e} is not finite"));
            }
            out.push(v);
        }
    }
    Ok(out)
}

/// A URI's `%XX` escapes decoded (others kept as written).
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (RFC 4648), padding optional, whitespace ignored.
pub(crate) fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    use base64::Engine as _;
    use base64::engine::{DecodePaddingMode, GeneralPurpose, GeneralPurposeConfig};
    const LENIENT: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
    );
    let compact: String = s.chars().filter(|c| !c.is_ascii_whitespace()).collect();
    LENIENT
        .decode(compact)
        .map_err(|e| format!("invalid base64: {e}"))
}

/// Standard base64 with padding.
pub(crate) fn base64_encode(data: &[u8]) -> String {
    use base64::Engine as _;
    base64::engine::general_purpose::STANDARD.encode(data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips() {
        for n in 0..20u8 {
            let data: Vec<u8> = (0..n).map(|i| i.wrapping_mul(37)).collect();
            assert_eq!(base64_decode(&base64_encode(&data)).unwrap(), data);
        }
        assert_eq!(base64_encode(b"Man"), "TWFu");
        assert_eq!(base64_decode("TWE=").unwrap(), b"Ma");
        assert!(base64_decode("TW!u").is_err());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("100%"), "100%");
    }
}
