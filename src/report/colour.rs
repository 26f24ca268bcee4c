//! Colours of figures: a palette that colour-blind readers can tell apart (Okabe–Ito) for
//! lines, and the viridis colour map (perceptually uniform, readable in grey) for time.

use plotters::style::RGBColor;

/// Line colours, in the order series are drawn (Okabe–Ito).
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
];

/// The colour of the `i`-th series (the palette repeats).
pub fn series_colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// Viridis at five stops; between them colours are interpolated linearly.
const VIRIDIS: [(f64, f64, f64); 5] = [
    (68.0, 1.0, 84.0),
    (59.0, 82.0, 139.0),
    (33.0, 145.0, 140.0),
    (94.0, 201.0, 98.0),
    (253.0, 231.0, 37.0),
];

/// The viridis colour at `s` in [0, 1] (clamped; NaN gives the start).
pub fn viridis(s: f64) -> RGBColor {
    let s = if s.is_nan() { 0.0 } else { s.clamp(0.0, 1.0) };
    let pos = s * (VIRIDIS.len() - 1) as f64;
    let k = (pos.floor() as usize).min(VIRIDIS.len() - 2);
    let f = pos - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round().clamp(0.0, 255.0) as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_runs_from_dark_purple_to_yellow_and_clamps() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(7.0), viridis(1.0));
        // Lightness (green channel) grows monotonically along the map.
        let greens: Vec<u8> = (0..=20).map(|i| viridis(i as f64 / 20.0).1).collect();
        assert!(greens.windows(2).all(|w| w[0] <= w[1]));
    }
}
