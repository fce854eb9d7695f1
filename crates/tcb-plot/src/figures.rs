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

/// A figure's plot of a 2D path (components x and y), titled.
fn path(title: &str) -> Plot {
    Plot {
        mode: Mode::Path { components: [0, 1] },
        ..titled(title)
    }
}

/// A figure drawn from the clip at `clip`.
fn figure(name: &'static str, clip: &'static str, plot: Plot) -> Figure {
    Figure { name, clip, plot }
}

/// Every figure, in the order docs/guide.md shows them, then the
/// README's (a test names the first one's clip).
pub fn figures() -> Vec<Figure> {
    let mut all = paper_figures();
    all.extend(guide_figures());
    all.push(readme_figure());
    all
}

/// The paper's figures 3 to 6, redrawn: tension, continuity, bias and the
/// careening ball.
fn paper_figures() -> Vec<Figure> {
    vec![
        figure(
            "tension.svg",
            "examples/clips/tension.json",
            path("Tension -1, 0, 1 (Kochanek & Bartels, fig. 3)"),
        ),
        figure(
            "continuity.svg",
            "examples/clips/continuity.json",
            path("Continuity -1, 0, 1 (fig. 4)"),
        ),
        figure(
            "bias.svg",
            "examples/clips/bias.json",
            path("Bias -1, 0, 1 (fig. 5)"),
        ),
        figure(
            "careen.svg",
            "examples/clips/careen.json",
            path("A ball careens off a tree (fig. 6)"),
        ),
    ]
}

/// The guide's own figures: uneven key spacing (path and speed), ease,
/// the extrapolation modes and squad against hermite.
fn guide_figures() -> Vec<Figure> {
    vec![
        figure(
            "spacing-path.svg",
            "examples/clips/spacing.json",
            path("Uneven key spacing: the four tangent rules (Eberly)"),
        ),
        figure(
            "spacing-speed.svg",
            "examples/clips/spacing.json",
            Plot {
                mode: Mode::Speed,
                inbetweens: Some(0),
                from: Some(0.0),
                to: Some(4.0),
                ..titled(
                    "Speed under the four tangent rules (Eberly): only 'uniform' jumps at the keys",
                )
            },
        ),
        figure(
            "ease.svg",
            "examples/clips/ease.json",
            Plot {
                inbetweens: Some(8),
                from: Some(0.0),
                to: Some(2.0),
                ..titled("Ease to and from the middle key: 0, 0.5, 1 (section 6)")
            },
        ),
        figure(
            "extrapolation.svg",
            "examples/clips/modes.json",
            Plot {
                from: Some(-1.5),
                to: Some(2.5),
                ..titled("Each pre/post mode outside the keys")
            },
        ),
        figure(
            "rotation.svg",
            "examples/clips/spin.json",
            Plot {
                tracks: vec!["top.squad".into(), "top.hermite".into()],
                from: Some(0.0),
                to: Some(2.0),
                ..titled("Squad against hermite on the same rotation keys")
            },
        ),
    ]
}

/// The README's figure: one set of keys under each parameter.
fn readme_figure() -> Figure {
    figure(
        "parameters.svg",
        "examples/clips/parameters.json",
        Plot {
            inbetweens: Some(0),
            from: Some(0.0),
            to: Some(4.0),
            ..titled("The same five keys: tension, continuity and bias (Kochanek & Bartels 1984)")
        },
    )
}
