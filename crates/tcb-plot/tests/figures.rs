//! The committed figures regenerate byte for byte from the committed clips
//! (`cargo run -p tcb-cli -- figures -o docs/figures` after a change).

use std::path::Path;

#[test]
fn figures_regenerate_byte_for_byte() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let figures = tcb_plot::figures();
    assert_eq!(figures.len(), 10);
    for f in &figures {
        let svg = f.render(&root).unwrap();
        let committed = std::fs::read_to_string(root.join("docs/figures").join(f.name))
            .unwrap_or_else(|e| panic!("docs/figures/{}: {e}", f.name));
        assert!(
            svg == committed,
            "docs/figures/{} differs from what {} draws now; regenerate with: cargo run -p tcb-cli -- figures -o docs/figures",
            f.name,
            f.clip
        );
    }
}

#[test]
fn every_mode_draws_every_kind() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for clip in [
        "examples/clips/bounce.json",
        "examples/clips/spin.json",
        "data/simple_skin.gltf",
    ] {
        let loaded = tcb_io::load(root.join(clip)).unwrap();
        for mode in [
            tcb_plot::Mode::Value,
            tcb_plot::Mode::Velocity,
            tcb_plot::Mode::Speed,
        ] {
            for t in loaded.clip.tracks() {
                let plot = tcb_plot::Plot {
                    tracks: vec![t.name.clone()],
                    mode,
                    ..tcb_plot::Plot::new(clip)
                };
                let svg = tcb_plot::render(&loaded.clip, &plot)
                    .unwrap_or_else(|e| panic!("{clip} {} {mode:?}: {e}", t.name));
                assert!(svg.contains("time (s)"), "{clip} {mode:?}");
            }
        }
    }
}

#[test]
fn bad_requests_are_one_clear_line() {
    let clip = tcb_io::ClipDoc::parse(
        r#"{"format": "tcb-clip/1", "tracks": [
          {"name": "x", "kind": "scalar", "times": [0, 1], "values": [0, 1]},
          {"name": "r", "kind": "quat", "times": [0, 1], "values": [[0,0,0,1],[0,0,1,0]]}]}"#,
    )
    .unwrap()
    .build()
    .unwrap();
    let try_plot = |plot: tcb_plot::Plot| tcb_plot::render(&clip, &plot).unwrap_err().to_string();
    let base = || tcb_plot::Plot::new("t");
    let e = try_plot(tcb_plot::Plot {
        tracks: vec!["nope".into()],
        ..base()
    });
    assert_eq!(e, "no track 'nope' (the clip has: x, r)");
    let e = try_plot(tcb_plot::Plot {
        from: Some(2.0),
        to: Some(1.0),
        ..base()
    });
    assert!(e.contains("time range 2 to 1 is empty"), "{e}");
    let e = try_plot(tcb_plot::Plot {
        tracks: vec!["x".into()],
        mode: tcb_plot::Mode::Path { components: [0, 1] },
        ..base()
    });
    assert!(e.contains("'x' is scalar"), "{e}");
    let e = try_plot(tcb_plot::Plot {
        tracks: vec!["x".into()],
        mode: tcb_plot::Mode::Components,
        ..base()
    });
    assert_eq!(
        e,
        "--components draws rotation tracks; 'x' is scalar (1 component)"
    );
    assert!(tcb_plot::parse_components("x,x").is_err());
    assert_eq!(tcb_plot::parse_components("x,z").unwrap(), [0, 2]);
}

#[test]
fn dense_capture_is_drawn_as_a_line_without_marks() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let cmu = tcb_io::load(root.join("data/cmu-01_01.bvh")).unwrap();
    let path = |clip: &tcb_core::SourceClip, track: &str| {
        let plot = tcb_plot::Plot {
            tracks: vec![track.into()],
            mode: tcb_plot::Mode::Path { components: [0, 2] },
            ..tcb_plot::Plot::new("t")
        };
        tcb_plot::render(clip, &plot).unwrap()
    };
    // 2752 keys: no key dots, handles or inbetweens thickening the line.
    let svg = path(&cmu.clip, "Hips.translation");
    assert_eq!(svg.matches("<circle").count(), 0);
    // A handful of keys keeps them.
    let careen = tcb_io::load(root.join("examples/clips/careen.json")).unwrap();
    let plot = tcb_plot::Plot {
        tracks: vec!["ball.path".into()],
        mode: tcb_plot::Mode::Path { components: [0, 1] },
        ..tcb_plot::Plot::new("t")
    };
    let svg = tcb_plot::render(&careen.clip, &plot).unwrap();
    assert!(svg.matches("<circle").count() > 20);
}
