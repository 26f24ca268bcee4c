//! Synthetic signals for the figure tests (unit tests here, `tests/report_html.rs`): a damped
//! oscillation and a force that depends on its velocity, with a little deterministic noise.
//! The checks on a rendered figure exist only in unit tests.

/// A synthetic record (SI units).
pub struct Signals {
    /// Time, s.
    pub t: Vec<f64>,
    /// Displacement, m.
    pub x: Vec<f64>,
    /// Velocity, m/s.
    pub v: Vec<f64>,
    /// Acceleration, m/s².
    pub a: Vec<f64>,
    /// Force, N.
    pub f: Vec<f64>,
}

/// `n` samples over `duration` seconds of x = 5 mm · e^(−0.3 t) sin(2π·2 t), with v and a
/// exact, and F = 20 v + 400 v|v| + noise (N).
pub fn damped_sine(n: usize, duration: f64) -> Signals {
    let w = 2.0 * std::f64::consts::PI * 2.0;
    let z = 0.3;
    let amp = 5e-3;
    let mut state = 7u64;
    let mut noise = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 33) as f64 / (1u64 << 31) as f64) - 0.5
    };
    let t: Vec<f64> = (0..n).map(|i| duration * i as f64 / n as f64).collect();
    let x: Vec<f64> = t
        .iter()
        .map(|t| amp * (-z * t).exp() * (w * t).sin())
        .collect();
    let v: Vec<f64> = t
        .iter()
        .map(|t| amp * (-z * t).exp() * (w * (w * t).cos() - z * (w * t).sin()))
        .collect();
    let a: Vec<f64> = t
        .iter()
        .map(|t| {
            amp * (-z * t).exp() * ((z * z - w * w) * (w * t).sin() - 2.0 * z * w * (w * t).cos())
        })
        .collect();
    let f: Vec<f64> = v
        .iter()
        .map(|v| 20.0 * v + 400.0 * v * v.abs() + 0.005 * noise())
        .collect();
    Signals { t, x, v, a, f }
}

/// Check that a figure's SVG and PNG exist, are non-empty, have text (the font works), every
/// text at least 8 pt in print and inside the canvas, the PNG has twice the drawing's `size`
/// and no coloured mark outside the SVG's coloured shapes; returns the CSV's columns.
#[cfg(test)]
pub fn assert_rendered(
    files: &super::FigureFiles,
    size: (u32, u32),
) -> Vec<super::series_csv::Column> {
    assert_prints_well(files, size);
    super::read_csv_columns(&files.csv).unwrap()
}

/// [`assert_rendered`] but for the CSV: the SVG and PNG.
#[cfg(test)]
pub fn assert_prints_well(files: &super::FigureFiles, size: (u32, u32)) {
    let svg = std::fs::read_to_string(&files.svg).unwrap();
    assert!(svg.len() > 1000, "SVG too small: {} bytes", svg.len());
    assert!(
        svg.contains("<svg") && svg.contains("<text"),
        "SVG has no text"
    );
    let png = std::fs::read(&files.png).unwrap();
    assert!(png.len() > 1000, "PNG too small: {} bytes", png.len());
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert_eq!((w, h), (size.0 * 2, size.1 * 2));
    let problems = super::print_problems(&svg, super::MIN_TEXT_PT).unwrap();
    assert!(
        problems.is_empty(),
        "{}: {}",
        files.svg.display(),
        problems.join("; ")
    );
    let stray = super::raster::stray_coloured_pixels(&svg, &png, 3.0);
    assert_eq!(
        stray,
        Ok(0),
        "{} has coloured marks outside its shapes",
        files.png.display()
    );
    let dir = files.png.parent().unwrap();
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// The column named `name`.
#[cfg(test)]
pub fn column<'a>(columns: &'a [super::series_csv::Column], name: &str) -> &'a [f64] {
    &columns
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no column {name:?}"))
        .values
}

/// The strokes of `svg`'s polylines in drawing order, `(colour as #RRGGBB, width)`, those of
/// `kinds` only, with each run of one kind told once: the order curves are drawn in (a later
/// one lies on top).
#[cfg(test)]
pub fn stroke_order(svg: &str, kinds: &[(String, u32)]) -> Vec<usize> {
    let attr = |line: &str, name: &str| {
        let (_, rest) = line.split_once(&format!(" {name}=\""))?;
        Some(rest.split_once('"')?.0.to_string())
    };
    let mut order: Vec<usize> = Vec::new();
    for line in svg
        .lines()
        .filter(|l| l.trim_start().starts_with("<polyline"))
    {
        let stroke = (attr(line, "stroke"), attr(line, "stroke-width"));
        let kind = kinds
            .iter()
            .position(|(c, w)| stroke == (Some(c.clone()), Some(w.to_string())));
        if let Some(k) = kind {
            if order.last() != Some(&k) {
                order.push(k);
            }
        }
    }
    order
}

/// A colour as plotters' SVG writes it.
#[cfg(test)]
pub fn hex(c: plotters::style::RGBColor) -> String {
    format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2)
}
