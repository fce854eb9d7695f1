//! An independent reader of what `tcb export` writes: the `gltf` crate
//! parses the GLB, and this file evaluates the samplers as the glTF 2.0
//! specification writes them (STEP, LINEAR with slerp, CUBICSPLINE with
//! tangents scaled by the key span) and composes the node hierarchy itself.
//! Nothing of tcb-io's importer is used. Model-space joint positions must
//! match `SkeletonBinding` on the clip that was exported, at 1e-5 relative.

use glam::{DAffine3, DQuat, DVec3};
use gltf::animation::{Interpolation, Property};
use std::sync::Arc;
use tcb_runtime::{Clip, Instance, SkeletonBinding};

/// One animation channel: key times and output elements (4 components;
/// vec3 outputs leave the last one 0).
struct Channel {
    node: usize,
    path: Property,
    interp: Interpolation,
    times: Vec<f64>,
    out: Vec<[f64; 4]>,
}

impl Channel {
    fn value(&self, k: usize) -> [f64; 4] {
        match self.interp {
            Interpolation::CubicSpline => self.out[3 * k + 1],
            _ => self.out[k],
        }
    }

    /// The channel at time `t`, as the glTF specification's Appendix C says.
    fn at(&self, t: f64) -> [f64; 4] {
        let n = self.times.len();
        if t <= self.times[0] {
            return self.value(0);
        }
        if t >= self.times[n - 1] {
            return self.value(n - 1);
        }
        let k = self.times.partition_point(|&x| x <= t) - 1;
        let td = self.times[k + 1] - self.times[k];
        let s = (t - self.times[k]) / td;
        let rotation = self.path == Property::Rotation;
        let (a, b) = (self.value(k), self.value(k + 1));
        let mut v = match self.interp {
            Interpolation::Step => a,
            Interpolation::Linear if rotation => {
                let (p, q) = (DQuat::from_array(a), DQuat::from_array(b));
                let q = if p.dot(q) < 0.0 { -q } else { q };
                let cos = p.dot(q).min(1.0);
                let angle = cos.acos();
                let r = if angle < 1e-9 {
                    p * (1.0 - s) + q * s
                } else {
                    p * (((1.0 - s) * angle).sin() / angle.sin())
                        + q * ((s * angle).sin() / angle.sin())
                };
                r.to_array()
            }
            Interpolation::Linear => std::array::from_fn(|c| a[c] + s * (b[c] - a[c])),
            Interpolation::CubicSpline => {
                let (s2, s3) = (s * s, s * s * s);
                let out_k = self.out[3 * k + 2];
                let in_k1 = self.out[3 * (k + 1)];
                std::array::from_fn(|c| {
                    (2.0 * s3 - 3.0 * s2 + 1.0) * a[c]
                        + td * (s3 - 2.0 * s2 + s) * out_k[c]
                        + (-2.0 * s3 + 3.0 * s2) * b[c]
                        + td * (s3 - s2) * in_k1[c]
                })
            }
        };
        if rotation {
            let l = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.iter_mut().for_each(|x| *x /= l);
        }
        v
    }
}

/// A glTF document read into plain data.
struct Scene {
    names: Vec<String>,
    parent: Vec<Option<usize>>,
    /// Rest translation, rotation, scale per node.
    rest: Vec<(DVec3, DQuat, DVec3)>,
    channels: Vec<Channel>,
}

fn read(bytes: &[u8]) -> Scene {
    let gltf = gltf::Gltf::from_slice(bytes).expect("the export is valid glTF");
    let blob = gltf.blob.clone().expect("a GLB has its binary chunk");
    let doc = gltf.document;
    let buffers = [blob];
    let n = doc.nodes().len();
    let mut parent = vec![None; n];
    for node in doc.nodes() {
        for c in node.children() {
            assert!(
                parent[c.index()].is_none(),
                "node {} has two parents",
                c.index()
            );
            parent[c.index()] = Some(node.index());
        }
    }
    let rest = doc
        .nodes()
        .map(|node| {
            let (t, r, s) = node.transform().decomposed();
            (
                DVec3::from(t.map(f64::from)),
                DQuat::from_array(r.map(f64::from)),
                DVec3::from(s.map(f64::from)),
            )
        })
        .collect();
    let anim = doc.animations().next().expect("one animation");
    let channels = anim
        .channels()
        .map(|ch| {
            let reader = ch.reader(|b| Some(&buffers[b.index()]));
            let times = reader.read_inputs().unwrap().map(f64::from).collect();
            use gltf::animation::util::ReadOutputs;
            let widen3 = |v: [f32; 3]| [v[0].into(), v[1].into(), v[2].into(), 0.0];
            let out = match reader.read_outputs().unwrap() {
                ReadOutputs::Translations(it) => it.map(widen3).collect(),
                ReadOutputs::Scales(it) => it.map(widen3).collect(),
                ReadOutputs::Rotations(it) => it.into_f32().map(|q| q.map(f64::from)).collect(),
                ReadOutputs::MorphTargetWeights(it) => it
                    .into_f32()
                    .map(|w| [f64::from(w), 0.0, 0.0, 0.0])
                    .collect(),
            };
            Channel {
                node: ch.target().node().index(),
                path: ch.target().property(),
                interp: ch.sampler().interpolation(),
                times,
                out,
            }
        })
        .collect();
    Scene {
        names: doc
            .nodes()
            .map(|n| n.name().unwrap_or_default().to_string())
            .collect(),
        parent,
        rest,
        channels,
    }
}

impl Scene {
    /// Model-space transform of every node at time `t`.
    fn model(&self, t: f64) -> Vec<DAffine3> {
        let mut trs = self.rest.clone();
        for ch in &self.channels {
            let v = ch.at(t);
            let (tr, r, s) = &mut trs[ch.node];
            match ch.path {
                Property::Translation => *tr = DVec3::new(v[0], v[1], v[2]),
                Property::Rotation => *r = DQuat::from_array(v),
                Property::Scale => *s = DVec3::new(v[0], v[1], v[2]),
                Property::MorphTargetWeights => {}
            }
        }
        let local: Vec<DAffine3> = trs
            .iter()
            .map(|(t, r, s)| DAffine3::from_scale_rotation_translation(*s, *r, *t))
            .collect();
        let mut model: Vec<Option<DAffine3>> = vec![None; local.len()];
        fn compose(
            i: usize,
            parent: &[Option<usize>],
            local: &[DAffine3],
            model: &mut [Option<DAffine3>],
        ) -> DAffine3 {
            if let Some(m) = model[i] {
                return m;
            }
            let m = match parent[i] {
                Some(p) => compose(p, parent, local, model) * local[i],
                None => local[i],
            };
            model[i] = Some(m);
            m
        }
        (0..local.len())
            .map(|i| compose(i, &self.parent, &local, &mut model))
            .collect()
    }
}

/// The bundled CMU clip, rotations in `mode`.
fn load_cmu(mode: tcb_core::RotationMode) -> tcb_io::Loaded {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/cmu-01_01.bvh");
    let options = tcb_io::ImportOptions::default().rotation(mode);
    tcb_io::load_with(std::path::Path::new(path), &options).unwrap()
}

/// Export the bundled CMU clip in `mode`, read it back here, and return the
/// worst relative model-space position difference over the clip.
fn cmu_worst(mode: tcb_core::RotationMode, max_error: f64) -> f64 {
    let loaded = load_cmu(mode);
    let skeleton = loaded.skeleton.clone().expect("BVH has a skeleton");
    let export = tcb_io::gltf_export::ExportOptions::default().max_error(max_error);
    let (glb, _) = tcb_io::gltf_export::export(
        &loaded.clip,
        Some(&skeleton),
        tcb_io::gltf_export::Container::Glb,
        &export,
    )
    .unwrap();
    let scene = read(&glb);
    // The hierarchy is the skeleton's: same names, same parents.
    assert_eq!(scene.names.len(), skeleton.joints().len());
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let node = scene.names.iter().position(|n| *n == joint.name).unwrap();
        let parent = scene.parent[node].map(|p| scene.names[p].as_str());
        let want = joint.parent.map(|p| skeleton.joints()[p].name.as_str());
        assert_eq!(parent, want, "parent of joint {j} ({})", joint.name);
    }
    let clip = Arc::new(Clip::compile(&loaded.clip));
    let binding = SkeletonBinding::new(skeleton.clone(), &clip);
    let mut instance = Instance::new(clip);
    let n = skeleton.joints().len();
    let mut local = vec![Default::default(); n];
    let mut model = vec![glam::Affine3A::IDENTITY; n];
    let nodes: Vec<usize> = skeleton
        .joints()
        .iter()
        .map(|j| scene.names.iter().position(|n| *n == j.name).unwrap())
        .collect();
    let end = loaded.clip.time_range().unwrap().1;
    let mut worst = 0.0f64;
    // Off the keys (120 fps keys, 97 ms apart here) and on the last one.
    for i in 0..=236 {
        let t = (i as f64 * 0.0973).min(end);
        binding
            .model_transforms(instance.sample(t), &mut local, &mut model)
            .unwrap();
        let theirs = scene.model(t);
        for (j, &node) in nodes.iter().enumerate() {
            let got = DVec3::from(model[j].translation.to_array().map(f64::from));
            let want = theirs[node].translation;
            worst = worst.max((got - want).length() / want.length().max(1.0));
        }
    }
    eprintln!("{mode:?}: worst relative position difference {worst:e}");
    worst
}

#[test]
fn exported_cmu_hermite_glb_gives_the_same_joint_positions() {
    let worst = cmu_worst(tcb_core::RotationMode::Hermite, 1e-5);
    assert!(worst < 1e-5, "worst relative position difference {worst}");
}

#[test]
fn exported_cmu_squad_glb_gives_the_same_joint_positions() {
    // Squad has no glTF form: the export resamples it as cubic pieces, here
    // within 1e-6 per component, and the positions then agree to 1e-5.
    let worst = cmu_worst(tcb_core::RotationMode::Squad, 1e-6);
    assert!(worst < 1e-5, "worst relative position difference {worst}");
}

/// The same check through three.js: with `TCB_THREEJS_POSITIONS` naming the
/// `positions.json` that `tools/gltf/viewer/shoot.mjs` wrote for the GLB of
/// `tcb export data/cmu-01_01.bvh` (squad, the default; `TCB_THREEJS_ROTATION=hermite`
/// for an export of the hermite import), three.js's GLTFLoader and
/// AnimationMixer put every joint where `SkeletonBinding` does, to 1e-5
/// relative. Skipped without it: CI has no browser.
#[test]
fn threejs_positions_match_skeleton_binding() {
    let Some(file) = std::env::var_os("TCB_THREEJS_POSITIONS") else {
        eprintln!("skipped: set TCB_THREEJS_POSITIONS (see tools/gltf/viewer/README.md)");
        return;
    };
    let mode = match std::env::var("TCB_THREEJS_ROTATION").as_deref() {
        Ok("hermite") => tcb_core::RotationMode::Hermite,
        _ => tcb_core::RotationMode::Squad,
    };
    let text = std::fs::read_to_string(&file).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let loaded = load_cmu(mode);
    let skeleton = loaded.skeleton.clone().unwrap();
    let clip = Arc::new(Clip::compile(&loaded.clip));
    let binding = SkeletonBinding::new(skeleton.clone(), &clip);
    let mut instance = Instance::new(clip);
    let n = skeleton.joints().len();
    let mut local = vec![Default::default(); n];
    let mut model = vec![glam::Affine3A::IDENTITY; n];
    let (mut worst, mut compared) = (0.0f64, 0);
    for (t, joints) in doc.as_object().unwrap() {
        binding
            .model_transforms(instance.sample(t.parse().unwrap()), &mut local, &mut model)
            .unwrap();
        for (j, joint) in skeleton.joints().iter().enumerate() {
            let p = &joints[joint.name.as_str()];
            let theirs = DVec3::new(
                p[0].as_f64().unwrap(),
                p[1].as_f64().unwrap(),
                p[2].as_f64().unwrap(),
            );
            let ours = DVec3::from(model[j].translation.to_array().map(f64::from));
            worst = worst.max((ours - theirs).length() / theirs.length().max(1.0));
            compared += 1;
        }
    }
    eprintln!("three.js: {compared} joint positions, worst relative difference {worst:e}");
    assert!(compared > 0);
    assert!(worst < 1e-5, "worst relative difference {worst}");
}
