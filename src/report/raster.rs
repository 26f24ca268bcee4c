//! The PNG of a figure is its SVG rasterised by resvg, so the two files are one picture.
//!
//! plotters' bitmap backend joins the segments of a thick polyline with unlimited miters: where
//! a loop or a noisy trace turns back on itself the join's offset lines meet far away, and the
//! PNG showed long straight spikes across the plot (the SVG, stroked by the browser, was
//! clean). resvg strokes with a miter limit and anti-aliases, and reads the same embedded font
//! ([`super::font`]) the SVG names, so no system font is needed. The PNG has twice the pixels
//! of the SVG's drawing units (its viewBox), sharp on a HiDPI screen and in print.
//!
//! ```no_run
//! # fn main() -> Result<(), String> {
//! let svg = r#"<svg xmlns="http://www.w3.org/2000/svg" width="10" height="10"/>"#;
//! let png: Vec<u8> = stf_lab::report::svg_to_png(svg)?;
//! # Ok(()) }
//! ```

use std::sync::{Arc, OnceLock};

use resvg::{tiny_skia, usvg};

use super::font::{DEJAVU_SANS, FAMILY};

pub(super) fn options() -> &'static usvg::Options<'static> {
    static OPTIONS: OnceLock<usvg::Options<'static>> = OnceLock::new();
    OPTIONS.get_or_init(|| {
        let mut fonts = usvg::fontdb::Database::new();
        fonts.load_font_data(DEJAVU_SANS.to_vec());
        let family = fonts
            .faces()
            .next()
            .and_then(|face| face.families.first().map(|(name, _)| name.clone()))
            .unwrap_or_else(|| FAMILY.to_string());
        fonts.set_sans_serif_family(family.clone());
        usvg::Options {
            font_family: family,
            fontdb: Arc::new(fonts),
            ..usvg::Options::default()
        }
    })
}

/// PNG pixels per unit of the SVG's drawing (its viewBox).
pub const PNG_SCALE: f32 = 2.0;

/// The drawing's size in its own units: the root's viewBox (plotters writes `viewBox="0 0 W
/// H"`), else `size`.
pub(super) fn drawing_size(svg: &str, size: usvg::Size) -> (f32, f32) {
    let view_box = svg
        .split_once("viewBox=\"")
        .and_then(|(_, rest)| rest.split_once('"'))
        .map(|(v, _)| {
            v.split_whitespace()
                .filter_map(|n| n.parse::<f32>().ok())
                .collect()
        })
        .filter(|v: &Vec<f32>| v.len() == 4 && v[2] > 0.0 && v[3] > 0.0);
    view_box.map_or((size.width(), size.height()), |v| (v[2], v[3]))
}

/// Rasterise an SVG document at [`PNG_SCALE`] pixels per drawing unit (a 600-unit-wide figure
/// is a 1 200-pixel PNG, whatever physical width the SVG states), white where it draws
/// nothing, to PNG bytes.
pub fn svg_to_png(svg: &str) -> Result<Vec<u8>, String> {
    let tree = usvg::Tree::from_str(svg, options()).map_err(|e| e.to_string())?;
    let (w, h) = drawing_size(svg, tree.size());
    let (pw, ph) = ((w * PNG_SCALE).round(), (h * PNG_SCALE).round());
    let mut pixmap = tiny_skia::Pixmap::new(pw as u32, ph as u32)
        .ok_or_else(|| format!("an empty image ({pw}×{ph})"))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    let size = tree.size();
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(pw / size.width(), ph / size.height()),
        &mut pixmap.as_mut(),
    );
    encode_opaque(&pixmap).map_err(|e| e.to_string())
}

/// PNG bytes of a pixmap drawn over white, as RGB (every pixel is opaque, so the alpha
/// channel carries nothing) at deflate level 1. tiny-skia's own encoder writes RGBA at the
/// balanced level (6): on the force-level discovery report of a 150 001-sample record (9
/// PNGs) that cost 0.35 s more CPU, about a quarter of the report's, for 2.2 MB of PNG
/// against 3.0 MB; `fdeflate` (the `png` crate's `Fast`) cost the same as level 1 and wrote
/// 3.9 MB.
fn encode_opaque(pixmap: &tiny_skia::Pixmap) -> Result<Vec<u8>, png::EncodingError> {
    let rgb: Vec<u8> = pixmap
        .pixels()
        .iter()
        .flat_map(|p| {
            let c = p.demultiply();
            [c.red(), c.green(), c.blue()]
        })
        .collect();
    let mut data = Vec::new();
    let mut encoder = png::Encoder::new(&mut data, pixmap.width(), pixmap.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_deflate_compression(png::DeflateCompression::Level(1));
    encoder.write_header()?.write_image_data(&rgb)?;
    Ok(data)
}

/// How many strongly coloured pixels of `png` lie more than `margin` drawing units outside every
/// coloured shape of `svg` (each shape's stroked bounding box): stray marks such as the
/// spikes the bitmap backend drew at sharp joins. Text and axes are black or grey, so they
/// are not counted. A check for tests (a figure's PNG against its SVG).
pub fn stray_coloured_pixels(svg: &str, png: &[u8], margin: f32) -> Result<usize, String> {
    let tree = usvg::Tree::from_str(svg, options()).map_err(|e| format!("SVG: {e}"))?;
    let mut boxes = Vec::new();
    collect_coloured_boxes(tree.root(), &mut boxes);
    let image = tiny_skia::Pixmap::decode_png(png).map_err(|e| format!("PNG: {e}"))?;
    let width = image.width() as usize;
    // PNG pixels in the units the shapes' boxes are in (the SVG's size), and the margin.
    let per_pixel = tree.size().width() / image.width() as f32;
    let (w, _) = drawing_size(svg, tree.size());
    let margin = margin * tree.size().width() / w;
    Ok(image
        .pixels()
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            let c = p.demultiply();
            let (hi, lo) = (
                c.red().max(c.green()).max(c.blue()),
                c.red().min(c.green()).min(c.blue()),
            );
            hi - lo > 80
        })
        .filter(|(i, _)| {
            let (x, y) = (
                ((i % width) as f32 + 0.5) * per_pixel,
                ((i / width) as f32 + 0.5) * per_pixel,
            );
            !boxes.iter().any(|b: &tiny_skia::Rect| {
                x >= b.left() - margin
                    && x <= b.right() + margin
                    && y >= b.top() - margin
                    && y <= b.bottom() + margin
            })
        })
        .count())
}

fn collect_coloured_boxes(group: &usvg::Group, boxes: &mut Vec<tiny_skia::Rect>) {
    let coloured = |paint: &usvg::Paint| match paint {
        usvg::Paint::Color(c) => {
            let (hi, lo) = (
                c.red.max(c.green).max(c.blue),
                c.red.min(c.green).min(c.blue),
            );
            hi - lo > 40
        }
        _ => true,
    };
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect_coloured_boxes(g, boxes),
            usvg::Node::Path(p) => {
                let stroked = p.stroke().is_some_and(|s| coloured(s.paint()));
                let filled = p.fill().is_some_and(|f| coloured(f.paint()));
                if stroked || filled {
                    boxes.push(p.abs_stroke_bounding_box());
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_noisy_thick_loop_leaves_no_marks_outside_its_shapes() {
        // Sharp reversals with thick lines: where the bitmap backend drew its spikes.
        let s = super::super::test_signals::damped_sine(6_000, 3.0);
        let zigzag: Vec<f64> =
            s.f.iter()
                .enumerate()
                .map(|(i, f)| f + if i % 2 == 0 { 0.05 } else { -0.05 })
                .collect();
        let dir = tempfile::tempdir().unwrap();
        let files = super::super::hysteresis(
            dir.path(),
            "zigzag",
            ("x, m", &s.x),
            ("F_STF, N", &zigzag),
            &s.t,
        )
        .unwrap();
        let svg = std::fs::read_to_string(&files.svg).unwrap();
        let png = std::fs::read(&files.png).unwrap();
        assert_eq!(stray_coloured_pixels(&svg, &png, 3.0), Ok(0));
    }

    #[test]
    fn the_png_has_twice_the_pixels_of_the_drawing_whatever_its_print_width() {
        let svg = r##"<svg width="85mm" height="42.5mm" viewBox="0 0 600 300" xmlns="http://www.w3.org/2000/svg"><rect x="300" y="0" width="300" height="300" fill="#0000FF"/></svg>"##;
        let png = tiny_skia::Pixmap::decode_png(&svg_to_png(svg).unwrap()).unwrap();
        assert_eq!((png.width(), png.height()), (1200, 600));
        // The drawing fills the PNG at that scale: the blue square is its right half.
        let at = |x: u32, y: u32| png.pixel(x, y).unwrap().demultiply();
        assert_eq!((at(598, 300).blue(), at(598, 300).red()), (255, 255));
        assert_eq!((at(602, 300).blue(), at(602, 300).red()), (255, 0));
        assert_eq!(at(1199, 599).blue(), 255);
    }
}
