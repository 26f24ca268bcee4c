//! The font figures are drawn with: DejaVu Sans, embedded in the binary and registered with
//! plotters as `sans-serif`, so PNG and SVG render on a machine with no font libraries
//! (see `assets/fonts/README.md` for its license).

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

use super::ReportError;

/// The family name figures use for all text.
pub const FAMILY: &str = "sans-serif";

pub(super) static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTERED: OnceLock<bool> = OnceLock::new();

/// Register the embedded font (once per process); every figure calls this before drawing.
pub fn ensure_registered() -> Result<(), ReportError> {
    let ok =
        *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, DEJAVU_SANS).is_ok());
    if ok {
        Ok(())
    } else {
        Err(ReportError::Font)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::style::IntoFont;

    #[test]
    fn registered_font_measures_text() {
        ensure_registered().unwrap();
        let font = (FAMILY, 20).into_font();
        let (w, h) = font.box_size("F_STF, N (ω, rad/s; a, m/s²)").unwrap();
        assert!(w > 100 && h > 10, "{w}×{h}");
    }
}
