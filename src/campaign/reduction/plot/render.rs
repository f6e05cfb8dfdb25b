//! Rendering a figure to PNG and SVG with `plotters`, without any system library: text is drawn
//! with the bundled DejaVu Sans (`assets/fonts`, Bitstream Vera licence) through plotters'
//! `ab_glyph` feature, the PNG is encoded by the `png` crate from plotters' RGB buffer, and the
//! SVG backend writes text as `<text>` elements (the viewer's sans-serif font).

use std::path::{Path, PathBuf};
use std::sync::Once;

use plotters::chart::MeshStyle;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::PlotError;
use crate::campaign::reduction::report::write_atomic;

/// The bundled font (DejaVu Sans 2.37; licence in `assets/fonts/LICENSE-DejaVu.txt`).
static FONT: &[u8] = include_bytes!("../../../../assets/fonts/DejaVuSans.ttf");

/// Font family name used by every figure.
pub const FONT_FAMILY: &str = "sans-serif";

/// Figure size in pixels (PNG) and user units (SVG).
pub const SIZE: (u32, u32) = (960, 640);

/// Registers the bundled font with plotters (once per process).
fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is compiled in; a failure here would be a broken build, reported on first use.
        let _ = plotters::style::register_font(FONT_FAMILY, FontStyle::Normal, FONT);
    });
}

/// A figure that can draw itself on any plotters backend.
pub trait Figure {
    /// Draws the whole figure on `root` (already filled white).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError>;
}

/// A drawing error: the message of plotters' error (generic over the backend, so kept as its
/// text) or of the PNG encoder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DrawError(pub String);

impl std::fmt::Display for DrawError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DrawError {}

/// Converts any plotters error to a [`DrawError`].
pub fn msg<E: std::fmt::Display>(e: E) -> DrawError {
    DrawError(e.to_string())
}

/// The figure as PNG bytes.
pub fn png_bytes(fig: &impl Figure, path: &Path) -> Result<Vec<u8>, PlotError> {
    register_font();
    let (w, h) = SIZE;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (w, h)).into_drawing_area();
        draw_on(fig, &root, path)?;
    }
    let mut out = Vec::new();
    let encode = |e: png::EncodingError| PlotError::Draw { path: path.to_path_buf(), message: msg(e) };
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Best);
    let mut writer = enc.write_header().map_err(encode)?;
    writer.write_image_data(&rgb).map_err(encode)?;
    writer.finish().map_err(encode)?;
    Ok(out)
}

/// The figure as SVG text.
pub fn svg_text(fig: &impl Figure, path: &Path) -> Result<String, PlotError> {
    register_font();
    let mut s = String::new();
    {
        let root = SVGBackend::with_string(&mut s, SIZE).into_drawing_area();
        draw_on(fig, &root, path)?;
    }
    Ok(s)
}

fn draw_on<DB: DrawingBackend>(fig: &impl Figure, root: &DrawingArea<DB, Shift>, path: &Path) -> Result<(), PlotError> {
    let err = |message: DrawError| PlotError::Draw { path: path.to_path_buf(), message };
    root.fill(&WHITE).map_err(msg).map_err(err)?;
    fig.draw(root).map_err(err)?;
    root.present().map_err(msg).map_err(err)
}

/// Writes `<stem>.png` and `<stem>.svg` atomically; returns both paths.
pub fn write_png_and_svg(fig: &impl Figure, stem: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let png = with_ext(stem, "png");
    let svg = with_ext(stem, "svg");
    write_atomic(&png, &png_bytes(fig, &png)?)?;
    write_atomic(&svg, svg_text(fig, &svg)?.as_bytes())?;
    Ok(vec![png, svg])
}

/// Writes one file whose format is chosen by the extension of `path` (`.png` or `.svg`).
pub fn write_by_extension(fig: &impl Figure, path: &Path) -> Result<(), PlotError> {
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("png") => write_atomic(path, &png_bytes(fig, path)?)?,
        Some("svg") => write_atomic(path, svg_text(fig, path)?.as_bytes())?,
        _ => return Err(PlotError::Format { path: path.to_path_buf() }),
    }
    Ok(())
}

fn with_ext(stem: &Path, ext: &str) -> PathBuf {
    let mut s = stem.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// Axis range `[lo, hi]` widened a little (log-wise when `log`), never empty.
pub fn padded_range(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = ((h - l) * 0.08).max(0.05);
        (10f64.powf(l - pad), 10f64.powf(h + pad))
    } else {
        let span = hi - lo;
        let pad = if span > 0.0 { span * 0.08 } else { lo.abs().max(1.0) * 0.1 };
        (lo - pad, hi + pad)
    }
}

/// Whether positive values spanning `lo..hi` deserve a log axis (more than one decade).
pub fn spans_decades(lo: f64, hi: f64) -> bool {
    lo > 0.0 && hi / lo > 10.0
}

/// Tick positions for a log axis over `[lo, hi]` (0 < lo < hi) that label the whole range, not
/// only its powers of ten: 1, 2, 5 × 10ᵏ, or every integer multiple 1…9 × 10ᵏ when that gives fewer
/// than four ticks (γ from 2.5 to 40 got one label, 10, from plotters' own choice); at most ~12.
/// No ticks for a range that is not such an interval (a zero, negative, reversed or non-finite
/// end has no decades to walk: `log10(0)` would make the walk run over 2³¹ of them).
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo > 0.0 && lo <= hi && hi.is_finite()) {
        return Vec::new();
    }
    let within = |mults: &[f64]| -> Vec<f64> {
        let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
        (k0..=k1)
            .flat_map(|k| mults.iter().map(move |m| m * 10f64.powi(k)))
            .filter(|&t| t >= lo * (1.0 - 1e-12) && t <= hi * (1.0 + 1e-12))
            .collect()
    };
    let coarse: Vec<f64> = within(&[1.0]);
    let mid = within(&[1.0, 2.0, 5.0]);
    let fine = within(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
    [fine, mid, coarse.clone()].into_iter().find(|t| t.len() >= 4 && t.len() <= 12).unwrap_or_else(|| {
        if coarse.len() > 12 {
            coarse
        } else {
            within(&[1.0, 2.0, 5.0])
        }
    })
}

/// The mesh of a figure in the figures' style: tick labels of both axes by [`tick`], at most two
/// light lines between ticks, tick labels at `size` and axis descriptions at `size + 2`.
pub fn styled_mesh<'m, 'a, 'b, X, Y, DB>(
    mesh: &'m mut MeshStyle<'a, 'b, X, Y, DB>,
    size: u32,
) -> &'m mut MeshStyle<'a, 'b, X, Y, DB>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
    DB: DrawingBackend,
{
    mesh.x_label_formatter(&tick_label)
        .y_label_formatter(&tick_label)
        .max_light_lines(2)
        .label_style((FONT_FAMILY, size))
        .axis_desc_style((FONT_FAMILY, size + 2))
}

/// [`tick`] of a label's value.
fn tick_label(x: &f64) -> String {
    tick(*x)
}

/// A tick or value label: at most 4 significant figures, trailing zeros dropped (`0.5`, `1.25`,
/// `0.0003512`), scientific outside 10⁻³ … 10⁵ (`1.0e-6`).
pub fn tick(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if (1e-3..1e5).contains(&x.abs()) {
        let s = crate::campaign::reduction::latex::sig_figs(x, 4);
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{x:.1e}")
    }
}

/// Draws the legend of `chart` at `pos` (white box, black border), as every figure does.
pub fn draw_legend<'a, DB: DrawingBackend + 'a, CT: CoordTranslate>(
    chart: &mut ChartContext<'a, DB, CT>,
    pos: SeriesLabelPosition,
) -> Result<(), DrawError> {
    chart
        .configure_series_labels()
        .position(pos)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT_FAMILY, 15))
        .draw()
        .map_err(msg)
}

/// Colours of the series (colour-blind-safe Okabe–Ito palette).
pub mod colour {
    use plotters::style::RGBColor;
    /// Ours.
    pub const OURS: RGBColor = RGBColor(0, 114, 178);
    /// The paper.
    pub const PAPER: RGBColor = RGBColor(213, 94, 0);
    /// Bounds and reference lines.
    pub const BOUND: RGBColor = RGBColor(0, 158, 115);
    /// The controller (σ-plot).
    pub const CONTROLLER: RGBColor = RGBColor(204, 121, 167);
    /// Markers, phase lines.
    pub const MARK: RGBColor = RGBColor(90, 90, 90);
}
