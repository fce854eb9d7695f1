//! The figures under `docs/figures/`: the seeds' pictures, redrawn from the
//! clips committed under `examples/clips/` (`tcb figures -o DIR` writes
//! them; a test checks they regenerate byte for byte).

use crate::plot::{Mode, Plot, PlotError};
use crate::render::render;
use std::path::Path;

/// One figure: its file name, the clip it comes from (relative to the
/// repository) and the plot.
#[derive(Clone, Debug)]
pub struct Figure {
    /// File name under `docs/figures/`, `.svg`.
    pub name: &'static str,
    /// The clip, relative to the repository's root.
    pub clip: &'static str,
    /// What is drawn.
    pub plot: Plot,
}

impl Figure {
    /// Draw it, reading the clip from under `root`.
    pub fn render(&self, root: &Path) -> Result<String, PlotError> {
        let path = root.join(self.clip);
        let loaded = tcb_io::load(&path).map_err(|e| PlotError(e.to_string()))?;
        render(&loaded.clip, &self.plot)
    }
}

/// A figure's plot: titled, without the track names after the title.
fn titled(title: &str) -> Plot {
    Plot {
        name_tracks: false,
        ..Plot::new(title)
    }
}

fn path(title: &str) -> Plot {
    Plot {
        mode: Mode::Path { components: [0, 1] },
        ..titled(title)
    }
}

/// Every figure, in the order docs/guide.md shows them, then the
/// README's (a test names the first one's clip).
pub fn figures() -> Vec<Figure> {
    vec![
        Figure {
            name: "tension.svg",
            clip: "examples/clips/tension.json",
            plot: path("Tension -1, 0, 1 (Kochanek & Bartels, fig. 3)"),
        },
        Figure {
            name: "continuity.svg",
            clip: "examples/clips/continuity.json",
            plot: path("Continuity -1, 0, 1 (fig. 4)"),
        },
        Figure {
            name: "bias.svg",
            clip: "examples/clips/bias.json",
            plot: path("Bias -1, 0, 1 (fig. 5)"),
        },
        Figure {
            name: "careen.svg",
            clip: "examples/clips/careen.json",
            plot: path("A ball careens off a tree (fig. 6)"),
        },
        Figure {
            name: "spacing-path.svg",
            clip: "examples/clips/spacing.json",
            plot: path("Uneven key spacing: the four tangent rules (Eberly)"),
        },
        Figure {
            name: "spacing-speed.svg",
            clip: "examples/clips/spacing.json",
            plot: Plot {
                mode: Mode::Speed,
                inbetweens: Some(0),
                from: Some(0.0),
                to: Some(4.0),
                ..titled(
                    "Speed under the four tangent rules (Eberly): only 'uniform' jumps at the keys",
                )
            },
        },
        Figure {
            name: "ease.svg",
            clip: "examples/clips/ease.json",
            plot: Plot {
                inbetweens: Some(8),
                from: Some(0.0),
                to: Some(2.0),
                ..titled("Ease to and from the middle key: 0, 0.5, 1 (section 6)")
            },
        },
        Figure {
            name: "extrapolation.svg",
            clip: "examples/clips/modes.json",
            plot: Plot {
                from: Some(-1.5),
                to: Some(2.5),
                ..titled("Each pre/post mode outside the keys")
            },
        },
        Figure {
            name: "rotation.svg",
            clip: "examples/clips/spin.json",
            plot: Plot {
                tracks: vec!["top.squad".into(), "top.hermite".into()],
                from: Some(0.0),
                to: Some(2.0),
                ..titled("Squad against hermite on the same rotation keys")
            },
        },
        Figure {
            name: "parameters.svg",
            clip: "examples/clips/parameters.json",
            plot: Plot {
                inbetweens: Some(0),
                from: Some(0.0),
                to: Some(4.0),
                ..titled(
                    "The same five keys: tension, continuity and bias (Kochanek & Bartels 1984)",
                )
            },
        },
    ]
}
