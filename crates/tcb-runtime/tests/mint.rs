//! Feature `mint`: a pose's values leave as `mint` types and come back.
#![cfg(feature = "mint")]

use std::sync::Arc;
use tcb_runtime::{Clip, Instance, mint};

#[test]
fn pose_values_convert_to_mint_and_back() {
    let clip = tcb_io::ClipDoc::parse(
        r#"{"format": "tcb-clip/1", "tracks": [
          {"name": "p", "kind": "vec3", "times": [0, 1], "values": [[0, 0, 0], [2, 4, 6]]},
          {"name": "r", "kind": "quat", "times": [0, 1], "values": [[0, 0, 0, 1], [0, 0, 1, 0]]}]}"#,
    )
    .unwrap()
    .build()
    .unwrap();
    let clip = Arc::new(Clip::compile(&clip));
    let (p, r) = (clip.track("p").unwrap(), clip.track("r").unwrap());
    let mut inst = Instance::new(clip);
    let pose = inst.sample(0.5);
    let v: mint::Vector3<f32> = pose.vec3(p).unwrap().into();
    let q: mint::Quaternion<f32> = pose.quat(r).unwrap().into();
    assert_eq!([v.x, v.y, v.z], [1.0, 2.0, 3.0]);
    assert_eq!(glam::Quat::from(q), pose.quat(r).unwrap());
}
