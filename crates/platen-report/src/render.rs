//! From figures to files: the SVG of every figure, PNG copies rendered from it, and the
//! figure folder and HTML page written through one atomic writer.
//!
//! PNG copies are rendered from the SVG by `resvg` (pure Rust, tiny-skia) with the text set in
//! Noto Sans, which is embedded in the binary (the `ttf-noto-sans` crate, Apache-2.0): no
//! system font is read, so the pixels are the same on every machine.

use std::fs;
use std::path::{Path, PathBuf};

use platen_io::{write_bytes_atomic, IoAction, IoError};

use crate::error::{ReportError, Result};
use crate::figure::Figure;

/// The size a verb's `--width`, `--height` and `--png-scale` ask for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FigureSize {
    /// Width of every figure, px (`None`: each figure's own, or kept in proportion to a
    /// given height).
    pub width_px: Option<u32>,
    /// Height of every figure, px (`None`: each figure's own, or kept in proportion to a
    /// given width).
    pub height_px: Option<u32>,
    /// PNG pixels per SVG pixel (2 gives a PNG twice as wide and high, for print).
    pub png_scale: f64,
}

impl Default for FigureSize {
    fn default() -> Self {
        Self {
            width_px: None,
            height_px: None,
            png_scale: 1.0,
        }
    }
}

impl FigureSize {
    /// The size of a figure drawn at `(width, height)` px by default: both given replace
    /// both; one given keeps the figure's proportions.
    pub fn of(&self, (width, height): (u32, u32)) -> (u32, u32) {
        let scaled = |x: u32, num: u32, den: u32| {
            ((f64::from(x) * f64::from(num) / f64::from(den.max(1))).round() as u32).max(1)
        };
        match (self.width_px, self.height_px) {
            (Some(w), Some(h)) => (w, h),
            (Some(w), None) => (w, scaled(height, w, width)),
            (None, Some(h)) => (scaled(width, h, height), h),
            (None, None) => (width, height),
        }
    }
}

/// The SVG of every figure, `(file name, svg)`.
///
/// # Errors
/// [`ReportError::Draw`] if a figure cannot be drawn.
pub fn render_all(figures: &[Figure]) -> Result<Vec<(String, String)>> {
    figures
        .iter()
        .map(|f| Ok((format!("{}.svg", f.name), f.to_svg()?)))
        .collect()
}

/// Writes what a verb's `--plot DIR` and `--report FILE.html` ask for: the figures (SVG and
/// PNG) at `size` to the folder and the page `html` makes of the figures and their SVG. The
/// figures are built only if one of the two is asked for. Returns the figure files written.
///
/// # Errors
/// Those of [`render_all`] and [`write_figures`]; [`ReportError::Write`] if the page cannot
/// be written.
pub fn write_outputs(
    plot_dir: Option<&Path>,
    report: Option<&Path>,
    size: &FigureSize,
    figures: impl FnOnce() -> Vec<Figure>,
    html: impl FnOnce(&[Figure], &[(String, String)]) -> String,
) -> Result<Vec<PathBuf>> {
    if plot_dir.is_none() && report.is_none() {
        return Ok(Vec::new());
    }
    let mut figures = figures();
    for f in &mut figures {
        f.size = size.of(f.size);
    }
    let rendered = render_all(&figures)?;
    let written = match plot_dir {
        Some(dir) => write_figures(dir, &rendered, size.png_scale)?,
        None => Vec::new(),
    };
    if let Some(path) = report {
        write_file(path, html(&figures, &rendered).as_bytes())?;
    }
    Ok(written)
}

/// Writes every figure to `dir` (created if missing) as SVG and PNG (`png_scale` PNG pixels
/// per SVG pixel), and returns the paths written. Every PNG is rendered before the first file is written, so a rendering failure
/// leaves the folder as it was; each file is written atomically.
///
/// # Errors
/// Those of [`svg_to_png`]; [`ReportError::Write`] if the folder cannot be made or a file
/// written.
pub fn write_figures(
    dir: &Path,
    rendered: &[(String, String)],
    png_scale: f64,
) -> Result<Vec<PathBuf>> {
    let mut files: Vec<(PathBuf, Vec<u8>)> = Vec::with_capacity(2 * rendered.len());
    for (file, svg) in rendered {
        files.push((dir.join(file), svg.as_bytes().to_vec()));
        files.push((
            dir.join(Path::new(file).with_extension("png")),
            svg_to_png(svg, png_scale)?,
        ));
    }
    fs::create_dir_all(dir).map_err(|source| IoError::Io {
        path: dir.to_path_buf(),
        action: IoAction::CreatingFolder,
        source,
    })?;
    let mut written = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        write_file(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// Renders an SVG document (as written by [`Figure::to_svg`]) to PNG at `scale` times its
/// own pixel size (1: the same size), with `sans-serif` text set in the embedded Noto Sans.
///
/// # Errors
/// [`ReportError::SvgParse`], [`ReportError::PixmapSize`] (also for a scale that is not
/// finite and positive), [`ReportError::PngEncode`].
pub fn svg_to_png(svg: &str, scale: f64) -> Result<Vec<u8>> {
    use resvg::{tiny_skia, usvg};
    let mut options = usvg::Options::default();
    let fonts = options.fontdb_mut();
    fonts.load_font_data(ttf_noto_sans::REGULAR.to_vec());
    fonts.set_sans_serif_family("Noto Sans");
    let tree =
        usvg::Tree::from_str(svg, &options).map_err(|e| ReportError::SvgParse(e.to_string()))?;
    let size = tree.size();
    let pixels = |x: f32| {
        let px = (f64::from(x) * scale).round();
        if px.is_finite() && px >= 1.0 && px <= f64::from(u32::MAX) {
            px as u32
        } else {
            0
        }
    };
    let (width, height) = (pixels(size.width()), pixels(size.height()));
    let mut pixmap =
        tiny_skia::Pixmap::new(width, height).ok_or(ReportError::PixmapSize { width, height })?;
    let transform = if scale == 1.0 {
        tiny_skia::Transform::default()
    } else {
        tiny_skia::Transform::from_scale(scale as f32, scale as f32)
    };
    resvg::render(&tree, transform, &mut pixmap.as_mut());
    pixmap
        .encode_png()
        .map_err(|e| ReportError::PngEncode(e.to_string()))
}

/// Every file this crate writes goes through here: written to a temporary file next to
/// `path`, then renamed onto it, so a failure leaves no partial file.
fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    write_bytes_atomic(path, bytes)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figure::{Panel, RECORDED};
    use crate::series::line;

    fn png_size(png: &[u8]) -> (u32, u32) {
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        let be = |b: &[u8]| u32::from_be_bytes(b.try_into().unwrap());
        (be(&png[16..20]), be(&png[20..24]))
    }

    /// Both sides given replace both; one keeps the proportions; none keeps the figure's.
    #[test]
    fn figure_size_of() {
        let size = |w, h| FigureSize {
            width_px: w,
            height_px: h,
            png_scale: 1.0,
        };
        assert_eq!(size(Some(800), Some(300)).of((1200, 900)), (800, 300));
        assert_eq!(size(Some(800), None).of((1200, 900)), (800, 600));
        assert_eq!(size(None, Some(450)).of((1200, 900)), (600, 450));
        assert_eq!(size(None, None).of((1260, 520)), (1260, 520));
    }

    /// The SVG is drawn at the size asked and the PNG at `png_scale` times it; rendering twice
    /// gives the same bytes.
    #[test]
    fn png_scale_multiplies_the_pixels() {
        let figure = Figure {
            name: "f".into(),
            title: "t".into(),
            caption: String::new(),
            panels: vec![Panel::new(
                "",
                "x",
                "y",
                vec![line("a", vec![(0.0, 0.0), (1.0, 2.0)], RECORDED, 2)],
            )],
            columns: 1,
            rows: Vec::new(),
            size: (640, 360),
        };
        let svg = figure.to_svg().unwrap();
        assert!(svg.contains("width=\"640\" height=\"360\""));
        assert_eq!(png_size(&svg_to_png(&svg, 1.0).unwrap()), (640, 360));
        let twice = svg_to_png(&svg, 2.0).unwrap();
        assert_eq!(png_size(&twice), (1280, 720));
        assert_eq!(twice, svg_to_png(&svg, 2.0).unwrap());
        assert!(svg_to_png(&svg, 0.0).is_err());
        assert!(svg_to_png(&svg, f64::NAN).is_err());
    }
}
