//! # tcb-plot
//!
//! SVG pictures of clips, drawn with `plotters` (pure Rust; text is left as
//! SVG `<text>` for the viewer to set, so no system fonts are needed):
//!
//! - value against time for each channel of the chosen tracks, keys marked
//!   and the extrapolation regions (outside the keys) shaded;
//! - velocity (d/dt per channel) or speed (the length of a vector track's
//!   velocity; angular speed for rotations);
//! - the 2D path of vector tracks (two chosen components), with keys,
//!   tangent handles and inbetween dots at equal time steps, so that their
//!   spacing shows speed, as in Kochanek and Bartels' figures;
//! - rotations as their angle and axis over time, or their 4 components.
//!
//! Any clip can be drawn: each kind of track (vectors, rotations, scalars)
//! gets a panel of its own, a mode skips the tracks it cannot draw
//! ([`Rendered::notes`] names them), and legends sit in a column beside
//! the charts, never over a curve.
//!
//! `tcb plot` and `tcb figures` are the command-line front ends; [`figures`]
//! lists the figures committed under `docs/figures/`.
//!
//! ```
//! let clip = tcb_io::ClipDoc::parse(r#"{"format": "tcb-clip/1", "tracks": [
//!   {"name": "ball.path", "kind": "vec2", "times": [0, 1, 2],
//!    "values": [[0, 0], [1, 2], [3, 0]]}]}"#)?.build()?;
//! let plot = tcb_plot::Plot {
//!     mode: tcb_plot::Mode::Path { components: [0, 1] },
//!     ..tcb_plot::Plot::new("ball")
//! };
//! let svg = tcb_plot::render(&clip, &plot)?;
//! assert!(svg.starts_with("<svg") && svg.contains("ball.path"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![forbid(unsafe_code)]

mod chart;
mod figures;
mod legend;
mod panel;
mod plot;
mod render;
mod sample;
mod select;
pub use figures::{Figure, figures};
pub use plot::{MAX_MARKED_KEYS, Mode, Plot, PlotError, Rendered, ground_plane, parse_components};
pub use render::{render, render_with_notes};
