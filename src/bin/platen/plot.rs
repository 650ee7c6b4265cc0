//! The figure size options shared by the verbs that write figures (`compare`, `identify`,
//! `simulate`, `sweep`): `--width`, `--height` and `--png-scale`.

use platen_report::FigureSize;

/// Smallest and largest figure side, px: below ~300 px the axis texts overlap, and a side
/// beyond 10 000 px (100 MB of PNG pixels) is a typing error rather than a figure.
const SIDE_PX: (u32, u32) = (300, 10_000);
/// Largest PNG side after `--png-scale`, px (the same bound on the pixel buffer).
const PNG_SIDE_MAX_PX: f64 = 20_000.0;

/// `--width`, `--height`, `--png-scale`.
#[derive(clap::Args, Debug, Clone, Copy)]
#[command(next_help_heading = "Figure size")]
pub struct SizeArgs {
    /// Width of every figure, px (300–10000; default each figure's own; with only --width
    /// the height keeps the figure's proportions).
    #[arg(long, value_name = "PX", value_parser = parse_side_px)]
    width: Option<u32>,
    /// Height of every figure, px (300–10000; with only --height the width keeps the
    /// figure's proportions).
    #[arg(long, value_name = "PX", value_parser = parse_side_px)]
    height: Option<u32>,
    /// PNG pixels per SVG pixel, 0.25–8 (2 for print: a PNG twice as wide and high; the SVG
    /// keeps --width/--height).
    #[arg(long, value_name = "F", default_value_t = 1.0, value_parser = parse_png_scale)]
    png_scale: f64,
}

impl SizeArgs {
    /// The size the options ask for; a PNG side beyond 20 000 px is a usage error.
    pub fn size(&self) -> FigureSize {
        let size = FigureSize {
            width_px: self.width,
            height_px: self.height,
            png_scale: self.png_scale,
        };
        let largest = size.of((1400, 1400));
        if f64::from(largest.0.max(largest.1)) * self.png_scale > PNG_SIDE_MAX_PX {
            clap::Error::raw(
                clap::error::ErrorKind::ValueValidation,
                format!(
                    "--png-scale {}: figures up to {} px a side would give PNGs over {} px\n",
                    self.png_scale,
                    largest.0.max(largest.1),
                    PNG_SIDE_MAX_PX
                ),
            )
            .exit();
        }
        size
    }
}

fn parse_side_px(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(px) if (SIDE_PX.0..=SIDE_PX.1).contains(&px) => Ok(px),
        _ => Err(format!(
            "`{s}`: expected a whole number of pixels from {} to {}",
            SIDE_PX.0, SIDE_PX.1
        )),
    }
}

fn parse_png_scale(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(f) if (0.25..=8.0).contains(&f) => Ok(f),
        _ => Err(format!("`{s}`: expected a factor from 0.25 to 8")),
    }
}

/// Prints a verb's `summary`: with `json`, as JSON with the figures `written` (when `--plot`
/// was given, `plotted`), else `text()`.
pub fn print(
    json: bool,
    plotted: bool,
    summary: &impl serde::Serialize,
    written: &[std::path::PathBuf],
    text: impl FnOnce() -> String,
) -> anyhow::Result<()> {
    if json {
        let figures = plotted.then_some(written);
        let value = platen_report::simulate_report::with_outputs(
            serde_json::to_value(summary)?,
            figures,
            None,
        );
        outln!("{}", serde_json::to_string_pretty(&value)?);
    } else {
        out!("{}", text());
    }
    Ok(())
}
