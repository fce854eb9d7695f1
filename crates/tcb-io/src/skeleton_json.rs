//! The clip file's optional `skeleton` (clip-format.md): joints with a
//! unique name, a parent index below their own (or `null`), and rest
//! `translation`, `rotation` (`[x, y, z, w]`) and `scale`, each optional.
//!
//! ```json
//! "skeleton": {"joints": [
//!   {"name": "Hips", "parent": null, "translation": [0, 0, 0]},
//!   {"name": "LeftUpLeg", "parent": 0, "translation": [1.36, -1.79, 0.84]}
//! ]}
//! ```

use crate::clip::{as_array, as_f32, as_object, as_str, check_fields, json_str, num32};
use crate::error::{Error, Location};
use glam::{Quat, Vec3};
use serde_json::Value as Json;
use std::collections::HashMap;
use std::fmt::Write as _;
use tcb_core::skeleton::{Joint, Skeleton, Transform};

const FIELDS: [&str; 5] = ["name", "parent", "translation", "rotation", "scale"];

/// Parse and validate a `skeleton` object.
pub(crate) fn parse(v: &Json) -> Result<Skeleton, Error> {
    let top = Location::default();
    let obj = as_object(v, &top, "skeleton")?;
    check_fields(obj, &["joints"], &top, "skeleton")?;
    let joints = match obj.get("joints") {
        Some(j) => as_array(j, &top, "skeleton joints")?,
        None => return Err(Error::invalid(top, "skeleton: missing \"joints\"")),
    };
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::with_capacity(joints.len());
    for (i, j) in joints.iter().enumerate() {
        let what = format!("skeleton joint {i}");
        let o = as_object(j, &top, &what)?;
        check_fields(o, &FIELDS, &top, &what)?;
        let name = match o.get("name") {
            Some(n) => as_str(n, &top, &format!("{what} name"))?.to_owned(),
            None => return Err(Error::invalid(top, format!("{what}: missing \"name\""))),
        };
        let what = format!("skeleton joint {i} '{name}'");
        if let Some(first) = seen.insert(name.clone(), i) {
            return Err(Error::invalid(
                top,
                format!("{what}: the name is already used by joint {first}"),
            ));
        }
        let parent = match o.get("parent") {
            None | Some(Json::Null) => None,
            Some(p) => match p.as_u64() {
                Some(p) if (p as usize) < i => Some(p as usize),
                Some(p) => {
                    return Err(Error::invalid(
                        top,
                        format!("{what}: parent {p} is not smaller than the joint's own index {i}"),
                    ));
                }
                None => {
                    return Err(Error::invalid(
                        top,
                        format!("{what}: parent must be a joint index or null, found {p}"),
                    ));
                }
            },
        };
        let numbers = |key: &str, n: usize, default: [f32; 4]| -> Result<[f32; 4], Error> {
            let Some(v) = o.get(key) else {
                return Ok(default);
            };
            let field = format!("{what} {key}");
            let a = as_array(v, &top, &field)?;
            if a.len() != n {
                return Err(Error::invalid(
                    top.clone(),
                    format!("{field} must have {n} numbers, found {}", a.len()),
                ));
            }
            let mut out = [0.0; 4];
            for (o, x) in out.iter_mut().zip(a) {
                *o = as_f32(x, &top, &field)?;
            }
            Ok(out)
        };
        let t = numbers("translation", 3, [0.0; 4])?;
        let r = numbers("rotation", 4, [0.0, 0.0, 0.0, 1.0])?;
        let s = numbers("scale", 3, [1.0, 1.0, 1.0, 0.0])?;
        let rotation = Quat::from_array(r);
        if rotation.length_squared() == 0.0 {
            return Err(Error::invalid(
                top,
                format!("{what}: rotation is zero (not a rotation)"),
            ));
        }
        out.push(Joint {
            name,
            parent,
            rest: Transform {
                translation: Vec3::new(t[0], t[1], t[2]),
                rotation: rotation.normalize(),
                scale: Vec3::new(s[0], s[1], s[2]),
            },
        });
    }
    Ok(Skeleton { joints: out })
}

/// Write `"skeleton": {...},` (one joint per line) into a clip's JSON.
pub(crate) fn write(skeleton: &Skeleton, out: &mut String) {
    let list = |v: &[f32]| v.iter().map(|&x| num32(x)).collect::<Vec<_>>().join(", ");
    out.push_str("  \"skeleton\": {\"joints\": [");
    for (i, j) in skeleton.joints.iter().enumerate() {
        out.push_str(if i == 0 { "\n" } else { ",\n" });
        let parent = j.parent.map_or("null".to_owned(), |p| p.to_string());
        let _ = write!(
            out,
            "    {{\"name\": {}, \"parent\": {parent}, \"translation\": [{}]",
            json_str(&j.name),
            list(&j.rest.translation.to_array())
        );
        if j.rest.rotation != Quat::IDENTITY {
            let _ = write!(
                out,
                ", \"rotation\": [{}]",
                list(&j.rest.rotation.to_array())
            );
        }
        if j.rest.scale != Vec3::ONE {
            let _ = write!(out, ", \"scale\": [{}]", list(&j.rest.scale.to_array()));
        }
        out.push('}');
    }
    out.push_str(if skeleton.joints.is_empty() {
        "]},\n"
    } else {
        "\n  ]},\n"
    });
}

#[cfg(test)]
mod tests {
    use crate::ClipDoc;

    fn clip(skeleton: &str) -> String {
        format!(
            r#"{{"format": "tcb-clip/1", "skeleton": {skeleton},
              "tracks": [{{"name": "a.rotation", "kind": "quat", "times": [0, 1],
                          "values": [[0, 0, 0, 1], [0, 0, 1, 0]]}}]}}"#
        )
    }

    #[test]
    fn a_skeleton_survives_writing_and_reading_exactly() {
        let text = clip(
            r#"{"joints": [
              {"name": "a", "parent": null, "translation": [0.1, 2, -3.25]},
              {"name": "b", "parent": 0, "translation": [1, 0, 0],
               "rotation": [0, 0.7071068, 0, 0.7071068], "scale": [1, 2, 1]},
              {"name": "b_end", "parent": 1}]}"#,
        );
        let doc = ClipDoc::parse(&text).unwrap();
        let s = doc.skeleton.as_ref().unwrap();
        assert_eq!(s.joints.len(), 3);
        assert_eq!(s.joints[1].parent, Some(0));
        assert_eq!(s.joints[2].rest.translation, glam::Vec3::ZERO);
        let again = ClipDoc::parse(&doc.to_json()).unwrap();
        assert_eq!(again, doc);
    }

    #[test]
    fn bad_skeletons_are_clear_errors() {
        let cases = [
            (
                r#"{"joints": [{"name": "a", "parent": 0}]}"#,
                "skeleton joint 0 'a': parent 0 is not smaller than the joint's own index 0",
            ),
            (
                r#"{"joints": [{"name": "a"}, {"name": "a", "parent": 0}]}"#,
                "skeleton joint 1 'a': the name is already used by joint 0",
            ),
            (
                r#"{"joints": [{"name": "a", "translation": [1, 1e999, 0]}]}"#,
                "skeleton joint 0 'a' translation 1e999 is not a finite number",
            ),
            (
                r#"{"joints": [{"name": "a", "rotation": [0, 0, 0, 0]}]}"#,
                "skeleton joint 0 'a': rotation is zero (not a rotation)",
            ),
            (
                r#"{"joints": [{"name": "a", "scale": [1, 1]}]}"#,
                "skeleton joint 0 'a' scale must have 3 numbers, found 2",
            ),
            (
                r#"{"joints": [{"name": "a", "parent": -1}]}"#,
                "skeleton joint 0 'a': parent must be a joint index or null, found -1",
            ),
            (
                r#"{"joints": [{"name": "a", "length": 2}]}"#,
                "unknown field \"length\" in skeleton joint 0",
            ),
            (r#"{"bones": []}"#, "unknown field \"bones\" in skeleton"),
        ];
        for (skeleton, message) in cases {
            let err = ClipDoc::parse(&clip(skeleton)).unwrap_err().to_string();
            assert!(err.contains(message), "{skeleton}: {err}");
        }
    }
}
