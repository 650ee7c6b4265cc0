//! The errors of drawing, rendering and writing figures and reports.

use platen_io::IoError;

/// Why a figure or a report could not be made or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// plotters failed to draw a figure.
    #[error("drawing a figure failed: {0}")]
    Draw(String),

    /// A figure's SVG could not be read back for PNG rendering.
    #[error("reading a figure's SVG for PNG rendering failed: {0}")]
    SvgParse(String),

    /// A figure's size cannot be rendered as a bitmap (the size is printed as tiny-skia's
    /// `IntSize` debug form, as it always was).
    #[error("a figure of IntSize {{ width: {width}, height: {height} }} px cannot be rendered")]
    PixmapSize {
        /// Width, px.
        width: u32,
        /// Height, px.
        height: u32,
    },

    /// A figure could not be encoded as PNG.
    #[error("encoding a figure as PNG failed: {0}")]
    PngEncode(String),

    /// A file or folder could not be written (the output is left as it was).
    #[error(transparent)]
    Write(#[from] IoError),
}

/// A result with a [`ReportError`].
pub type Result<T, E = ReportError> = std::result::Result<T, E>;
