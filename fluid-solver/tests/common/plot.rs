//! Colours for the pictures the case tests draw (`pressure.png` of the case folders).

use plotters::style::RGBColor;

/// A blue-white-red colour for `v` in `[-1, 1]` (clamped): white at 0, red above, blue below.
pub fn diverging(v: f64) -> RGBColor {
    let v = v.clamp(-1.0, 1.0);
    let fade = |c: f64| (255.0 * (1.0 - v.abs()) + c * v.abs()) as u8;
    if v >= 0.0 {
        RGBColor(fade(200.0), fade(30.0), fade(30.0))
    } else {
        RGBColor(fade(30.0), fade(60.0), fade(200.0))
    }
}
