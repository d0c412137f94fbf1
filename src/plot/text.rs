//! Text for plots without a font engine: a 5×7 pixel capital-letter font drawn pixel by
//! pixel (each font pixel a square of `scale`×`scale`), so PNG plots can carry titles, legends and tick labels in metres.
//!
//! Not for: typesetting (no lowercase, no kerning, no Unicode beyond a few signs); lowercase
//! letters are drawn as capitals and unknown characters as `?`.

use plotters::prelude::*;

/// Glyph width and height in font pixels; each glyph advances by `WIDTH + 1`.
pub const WIDTH: i32 = 5;
/// Glyph height in font pixels; lines advance by `HEIGHT + 3`.
pub const HEIGHT: i32 = 7;

/// Rows of one glyph, top first, bit 4 the leftmost pixel.
fn glyph(c: char) -> [u8; 7] {
    match c.to_ascii_uppercase() {
        '0' => [14, 17, 19, 21, 25, 17, 14],
        '1' => [4, 12, 4, 4, 4, 4, 14],
        '2' => [14, 17, 1, 2, 4, 8, 31],
        '3' => [31, 2, 4, 2, 1, 17, 14],
        '4' => [2, 6, 10, 18, 31, 2, 2],
        '5' => [31, 16, 30, 1, 1, 17, 14],
        '6' => [6, 8, 16, 30, 17, 17, 14],
        '7' => [31, 1, 2, 4, 8, 8, 8],
        '8' => [14, 17, 17, 14, 17, 17, 14],
        '9' => [14, 17, 17, 15, 1, 2, 12],
        'A' => [14, 17, 17, 31, 17, 17, 17],
        'B' => [30, 17, 17, 30, 17, 17, 30],
        'C' => [14, 17, 16, 16, 16, 17, 14],
        'D' => [28, 18, 17, 17, 17, 18, 28],
        'E' => [31, 16, 16, 30, 16, 16, 31],
        'F' => [31, 16, 16, 30, 16, 16, 16],
        'G' => [14, 17, 16, 23, 17, 17, 15],
        'H' => [17, 17, 17, 31, 17, 17, 17],
        'I' => [14, 4, 4, 4, 4, 4, 14],
        'J' => [7, 2, 2, 2, 2, 18, 12],
        'K' => [17, 18, 20, 24, 20, 18, 17],
        'L' => [16, 16, 16, 16, 16, 16, 31],
        'M' => [17, 27, 21, 21, 17, 17, 17],
        'N' => [17, 17, 25, 21, 19, 17, 17],
        'O' => [14, 17, 17, 17, 17, 17, 14],
        'P' => [30, 17, 17, 30, 16, 16, 16],
        'Q' => [14, 17, 17, 17, 21, 18, 13],
        'R' => [30, 17, 17, 30, 20, 18, 17],
        'S' => [15, 16, 16, 14, 1, 1, 30],
        'T' => [31, 4, 4, 4, 4, 4, 4],
        'U' => [17, 17, 17, 17, 17, 17, 14],
        'V' => [17, 17, 17, 17, 17, 10, 4],
        'W' => [17, 17, 17, 21, 21, 21, 10],
        'X' => [17, 17, 10, 4, 10, 17, 17],
        'Y' => [17, 17, 17, 10, 4, 4, 4],
        'Z' => [31, 1, 2, 4, 8, 16, 31],
        ' ' => [0; 7],
        '.' => [0, 0, 0, 0, 0, 12, 12],
        ',' => [0, 0, 0, 0, 12, 4, 8],
        '-' | '−' | '–' => [0, 0, 0, 31, 0, 0, 0],
        ':' => [0, 12, 12, 0, 12, 12, 0],
        ';' => [0, 12, 12, 0, 12, 4, 8],
        '/' => [0, 1, 2, 4, 8, 16, 0],
        '(' => [2, 4, 8, 8, 8, 4, 2],
        ')' => [8, 4, 2, 2, 2, 4, 8],
        '[' => [14, 8, 8, 8, 8, 8, 14],
        ']' => [14, 2, 2, 2, 2, 2, 14],
        '=' => [0, 0, 31, 0, 31, 0, 0],
        '%' => [24, 25, 2, 4, 8, 19, 3],
        '+' => [0, 4, 4, 31, 4, 4, 0],
        '>' => [8, 4, 2, 1, 2, 4, 8],
        '<' => [2, 4, 8, 16, 8, 4, 2],
        '≥' => [8, 4, 2, 4, 8, 0, 31],
        '≤' => [2, 4, 8, 4, 2, 0, 31],
        '_' => [0, 0, 0, 0, 0, 0, 31],
        '\'' => [4, 4, 8, 0, 0, 0, 0],
        '#' => [10, 10, 31, 10, 31, 10, 10],
        '*' | '×' => [0, 17, 10, 4, 10, 17, 0],
        '·' => [0, 0, 0, 12, 12, 0, 0],
        _ => [14, 17, 1, 2, 4, 0, 4],
    }
}

/// Width in pixels of `text` drawn at `scale` (pixels per font pixel).
pub fn text_width(text: &str, scale: u32) -> i32 {
    let n = text.chars().count() as i32;
    if n == 0 {
        0
    } else {
        (n * (WIDTH + 1) - 1) * scale.max(1) as i32
    }
}

/// Draws `text` with its top-left corner at pixel `(x, y)` of `area`, each font pixel a
/// `scale`×`scale` square of `colour`.
pub fn draw_text<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    (x, y): (i32, i32),
    scale: u32,
    colour: RGBColor,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let s = scale.max(1) as i32;
    for (k, c) in text.chars().enumerate() {
        let x0 = x + k as i32 * (WIDTH + 1) * s;
        for (row, bits) in glyph(c).iter().enumerate() {
            for col in 0..WIDTH {
                if bits & (1 << (WIDTH - 1 - col)) != 0 {
                    let px = x0 + col * s;
                    let py = y + row as i32 * s;
                    for dy in 0..s {
                        for dx in 0..s {
                            area.draw_pixel((px + dx, py + dy), &colour)?;
                        }
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn glyphs_fit_five_columns_and_lowercase_matches_capitals() {
        for c in "0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ .,-:;/()[]=%+><≥≤_'#*·?".chars() {
            assert!(glyph(c).iter().all(|&r| r < 32), "{c}");
        }
        assert_eq!(glyph('a'), glyph('A'));
        assert_ne!(glyph('O'), glyph('0'));
        assert_eq!(text_width("", 2), 0);
        assert_eq!(text_width("AB", 1), 11);
        assert_eq!(text_width("AB", 2), 22);
    }

    #[test]
    fn text_is_drawn_where_asked() {
        let (w, h) = (40u32, 12u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            draw_text(&root, "1", (2, 2), 1, RGBColor(0, 0, 0)).unwrap();
            root.present().unwrap();
        }
        let dark = |x: u32, y: u32| buf[((y * w + x) * 3) as usize] == 0;
        // the foot of the `1` spans columns 1..=3 of its cell, at row 6
        assert!(dark(3, 8) && dark(4, 8) && dark(5, 8));
        assert!(!dark(2, 8) && !dark(6, 8));
        // nothing outside the 5×7 cell
        let outside = (0..w)
            .flat_map(|x| (0..h).map(move |y| (x, y)))
            .filter(|&(x, y)| !(2..7).contains(&x) || !(2..9).contains(&y))
            .any(|(x, y)| dark(x, y));
        assert!(!outside);
    }
}
