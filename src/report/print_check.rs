//! What a figure's text looks like in print, read back from its SVG: every text's size in
//! points at the width the SVG states (`width="85mm"`; one journal column, 85 mm, when it
//! states none) and whether its box, as the embedded font lays it out, lies inside the canvas.
//! The figures' tests and the bundled reports' tests hold every figure to
//! [`super::figure::MIN_TEXT_PT`] and to no clipped text.

use resvg::usvg;

use super::raster::{drawing_size, options};

/// Millimetres in a point.
const MM_PER_PT: f64 = 25.4 / 72.0;
/// The print width of an SVG that states none: one journal column, mm.
const DEFAULT_PRINT_MM: f64 = 85.0;

/// One text of a figure as it prints.
#[derive(Clone, Debug, PartialEq)]
pub struct PrintedText {
    /// The text.
    pub text: String,
    /// Its smallest font size, points at the print width.
    pub points: f64,
    /// Whether its laid-out box lies inside the canvas (half a drawing unit of slack).
    pub inside: bool,
}

/// The print width the SVG's root states, mm, if it states one in millimetres.
fn stated_width_mm(svg: &str) -> Option<f64> {
    let root = &svg[svg.find("<svg")?..];
    let root = &root[..root.find('>')?];
    let (_, rest) = root.split_once(" width=\"")?;
    rest.split_once('"')?.0.strip_suffix("mm")?.parse().ok()
}

/// Every text of `svg` as it prints (see [`PrintedText`]), in document order.
pub fn printed_texts(svg: &str) -> Result<Vec<PrintedText>, String> {
    let tree = usvg::Tree::from_str(svg, options()).map_err(|e| format!("SVG: {e}"))?;
    let (w, _) = drawing_size(svg, tree.size());
    let mm_per_unit = stated_width_mm(svg).unwrap_or(DEFAULT_PRINT_MM) / f64::from(w);
    let canvas = tree.size();
    let mut out = Vec::new();
    collect(tree.root(), &mut |text: &usvg::Text| {
        let smallest = text
            .chunks()
            .iter()
            .flat_map(|c| c.spans())
            .map(|s| f64::from(s.font_size().get()))
            .fold(f64::INFINITY, f64::min);
        let b = text.abs_bounding_box();
        let slack = 0.5 * canvas.width() / w;
        out.push(PrintedText {
            text: text.chunks().iter().map(|c| c.text()).collect(),
            points: smallest * mm_per_unit / MM_PER_PT,
            inside: b.left() >= -slack
                && b.top() >= -slack
                && b.right() <= canvas.width() + slack
                && b.bottom() <= canvas.height() + slack,
        });
    });
    Ok(out)
}

fn collect(group: &usvg::Group, on_text: &mut impl FnMut(&usvg::Text)) {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => collect(g, on_text),
            usvg::Node::Text(t) => on_text(t),
            _ => {}
        }
    }
}

/// What is wrong with `svg`'s text in print: each text under `min_points` or reaching past
/// the canvas, one line each (none: it prints well).
pub fn print_problems(svg: &str, min_points: f64) -> Result<Vec<String>, String> {
    let texts = printed_texts(svg)?;
    if texts.is_empty() {
        return Err("no text (the font did not load?)".into());
    }
    Ok(texts
        .iter()
        .flat_map(|t| {
            let small = (t.points < min_points)
                .then(|| format!("{:?} is {:.1} pt (< {min_points} pt)", t.text, t.points));
            let clipped = (!t.inside).then(|| format!("{:?} reaches past the canvas", t.text));
            small.into_iter().chain(clipped)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = r#"<svg width="85mm" height="42.5mm" viewBox="0 0 600 300" xmlns="http://www.w3.org/2000/svg">"#;

    #[test]
    fn sizes_are_points_at_the_stated_width_and_clipped_text_is_found() {
        let svg = format!(
            "{HEAD}<text x=\"10\" y=\"50\" font-family=\"sans-serif\" font-size=\"20\">fits</text>\
             <text x=\"580\" y=\"100\" font-family=\"sans-serif\" font-size=\"12\">clipped</text></svg>"
        );
        let texts = printed_texts(&svg).unwrap();
        assert_eq!(texts.len(), 2);
        // 20 units of a 600-unit drawing 85 mm wide: 2.83 mm, 8.03 pt.
        assert!((texts[0].points - 20.0 * 85.0 / 600.0 / MM_PER_PT).abs() < 1e-3);
        assert!(texts[0].inside && !texts[1].inside);
        let problems = print_problems(&svg, 8.0).unwrap();
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(
            problems[0].contains("\"clipped\" is 4.8 pt"),
            "{problems:?}"
        );
        assert!(
            problems[1].contains("\"clipped\" reaches past"),
            "{problems:?}"
        );
    }

    #[test]
    fn an_svg_without_a_physical_width_prints_one_column_wide() {
        let svg = r#"<svg width="1000" height="600" viewBox="0 0 1000 600" xmlns="http://www.w3.org/2000/svg"><text x="10" y="50" font-family="sans-serif" font-size="12">x</text></svg>"#;
        let t = &printed_texts(svg).unwrap()[0];
        assert!((t.points - 12.0 * 0.085 / MM_PER_PT).abs() < 1e-3, "{t:?}");
    }

    #[test]
    fn rotated_text_is_measured_where_it_lies() {
        // An axis description rotated to run down the left edge, as plotters writes it.
        let at = |x: u32| {
            format!(
                "{HEAD}<text x=\"{x}\" y=\"150\" dy=\"0.5ex\" text-anchor=\"middle\" \
                 font-family=\"sans-serif\" font-size=\"22\" transform=\"rotate(270, {x}, 150)\">\
                 displacement x, mm</text></svg>"
            )
        };
        assert!(printed_texts(&at(20)).unwrap()[0].inside);
        assert!(!printed_texts(&at(4)).unwrap()[0].inside);
    }
}
