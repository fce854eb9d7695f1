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

use crate::error::{Error, Location};
use crate::json::finite_f32;
use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use tcb_core::skeleton::{Joint, Skeleton, Transform};

/// `skeleton` as read (validated by [`SkeletonIn::into_skeleton`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SkeletonIn {
    joints: Vec<JointIn>,
    #[serde(default, rename = "extras")]
    _extras: Option<crate::json::Extras>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointIn {
    name: String,
    #[serde(default)]
    parent: Option<f64>,
    #[serde(default)]
    translation: Option<Vec<f64>>,
    #[serde(default)]
    rotation: Option<Vec<f64>>,
    #[serde(default)]
    scale: Option<Vec<f64>>,
    #[serde(default, rename = "extras")]
    _extras: Option<crate::json::Extras>,
}

impl SkeletonIn {
    /// The skeleton, or the first joint that breaks the contract.
    pub(crate) fn into_skeleton(self) -> Result<Skeleton, Error> {
        let top = Location::default();
        let mut seen: HashMap<String, usize> = HashMap::new();
        let mut out = Vec::with_capacity(self.joints.len());
        for (i, j) in self.joints.into_iter().enumerate() {
            let what = format!("skeleton joint {i} '{}'", j.name);
            if let Some(first) = seen.insert(j.name.clone(), i) {
                return Err(Error::invalid(
                    top,
                    format!("{what}: the name is already used by joint {first}"),
                ));
            }
            let parent = match j.parent {
                None => None,
                Some(p) if p >= 0.0 && p.fract() == 0.0 && p < i as f64 => Some(p as usize),
                Some(p) if p >= 0.0 && p.fract() == 0.0 => {
                    return Err(Error::invalid(
                        top,
                        format!("{what}: parent {p} is not smaller than the joint's own index {i}"),
                    ));
                }
                Some(p) => {
                    return Err(Error::invalid(
                        top,
                        format!("{what}: parent must be a joint index or null, found {p}"),
                    ));
                }
            };
            let numbers = |key: &str, v: Option<Vec<f64>>, n: usize, default: [f32; 4]| {
                let Some(v) = v else {
                    return Ok(default);
                };
                let field = format!("{what} {key}");
                if v.len() != n {
                    return Err(Error::invalid(
                        top.clone(),
                        format!("{field} must have {n} numbers, found {}", v.len()),
                    ));
                }
                let mut out = [0.0; 4];
                for (o, x) in out.iter_mut().zip(v) {
                    *o = finite_f32(x, &field).map_err(|m| Error::invalid(top.clone(), m))?;
                }
                Ok(out)
            };
            let t = numbers("translation", j.translation, 3, [0.0; 4])?;
            let r = numbers("rotation", j.rotation, 4, [0.0, 0.0, 0.0, 1.0])?;
            let s = numbers("scale", j.scale, 3, [1.0, 1.0, 1.0, 0.0])?;
            let rotation = Quat::from_array(r);
            if rotation.length_squared() == 0.0 {
                return Err(Error::invalid(
                    top,
                    format!("{what}: rotation is zero (not a rotation)"),
                ));
            }
            let rotation = unit_rotation(rotation);
            out.push(Joint {
                name: j.name,
                parent,
                rest: Transform {
                    translation: Vec3::new(t[0], t[1], t[2]),
                    rotation,
                    scale: Vec3::new(s[0], s[1], s[2]),
                },
            });
        }
        Ok(Skeleton::new(out).expect("each parent checked to be below its joint above"))
    }
}

/// How far a rotation's squared length may be from 1 and still count as
/// unit: a normalized f32 quaternion is within a few ulps of 1 (2.4e-7).
const UNIT: f32 = 1e-6;

/// `q` normalized, unless it is already unit (within [`UNIT`]): then as it
/// is, bit for bit. Normalizing again could move a component by an ulp,
/// so the reader, the writer and the glTF importer all use this, and a
/// rest rotation written then read is the one written.
pub(crate) fn unit_rotation(q: Quat) -> Quat {
    if (q.length_squared() - 1.0).abs() <= UNIT {
        q
    } else {
        q.normalize()
    }
}

/// `skeleton` as written: one joint per line; `rotation` and `scale` only
/// where they are not the identity.
#[derive(Serialize)]
pub(crate) struct SkeletonOut<'a> {
    joints: Vec<JointOut<'a>>,
}

#[derive(Serialize)]
struct JointOut<'a> {
    name: &'a str,
    parent: Option<usize>,
    translation: [f32; 3],
    #[serde(skip_serializing_if = "Option::is_none")]
    rotation: Option<[f32; 4]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    scale: Option<[f32; 3]>,
}

impl<'a> SkeletonOut<'a> {
    pub(crate) fn of(skeleton: &'a Skeleton) -> Self {
        SkeletonOut {
            joints: skeleton
                .joints()
                .iter()
                .map(|j| JointOut {
                    name: &j.name,
                    parent: j.parent,
                    translation: j.rest.translation.to_array(),
                    rotation: (j.rest.rotation != Quat::IDENTITY)
                        .then(|| unit_rotation(j.rest.rotation).to_array()),
                    scale: (j.rest.scale != Vec3::ONE).then(|| j.rest.scale.to_array()),
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::clip_json::ClipDoc;

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
        assert_eq!(s.joints().len(), 3);
        assert_eq!(s.joints()[1].parent, Some(0));
        assert_eq!(s.joints()[2].rest.translation, glam::Vec3::ZERO);
        let again = ClipDoc::parse(&doc.to_json()).unwrap();
        assert_eq!(again, doc);
    }

    #[test]
    fn unit_rotations_are_kept_and_normalizing_is_done_once() {
        use super::unit_rotation;
        use glam::Quat;
        // Random directions and lengths (an LCG; no dependency needed).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
        };
        for _ in 0..100_000 {
            let q = Quat::from_xyzw(next(), next(), next(), next()) * (2.0 + next());
            if q.length_squared() == 0.0 {
                continue;
            }
            let u = unit_rotation(q);
            assert!((u.length() - 1.0).abs() < 1e-6, "{q:?}");
            assert_eq!(
                unit_rotation(u).to_array().map(f32::to_bits),
                u.to_array().map(f32::to_bits)
            );
        }
        let q = Quat::from_rotation_y(1.0);
        assert_eq!(unit_rotation(q), q);
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
                "skeleton joint 0: translation 1e999 is not a finite number",
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
                "skeleton joint 0: unknown field \"length\"",
            ),
            (r#"{"bones": []}"#, "skeleton: unknown field \"bones\""),
        ];
        for (skeleton, message) in cases {
            let err = ClipDoc::parse(&clip(skeleton)).unwrap_err().to_string();
            assert!(err.contains(message), "{skeleton}: {err}");
        }
    }
}
