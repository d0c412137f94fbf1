//! The fixed colour palette used when exporting labelled points (segmented planes, clusters)
//! to LAS and PLY, so that every viewer shows the same label in the same colour.
//!
//! Label 0 means "unlabelled" and is grey. Every other label gets a saturated colour whose hue
//! steps around the colour wheel by the golden angle, so consecutive labels are far apart in
//! hue and no label is ever grey.
//!
//! Not for: reading or writing files (see [`super::las_io`] and [`super::ply_io`]).

/// The colour of unlabelled points (label 0).
pub const UNLABELLED_COLOUR: [u8; 3] = [128, 128, 128];

/// The RGB colour (8 bits a channel) of `label`; deterministic, [`UNLABELLED_COLOUR`] for 0.
pub fn label_colour(label: u32) -> [u8; 3] {
    if label == 0 {
        return UNLABELLED_COLOUR;
    }
    // Golden-ratio hue steps; two saturation/value levels alternate every cycle so that labels
    // whose hues come close are still told apart by brightness.
    let golden = 0.618_033_988_749_895_f64;
    let hue = (f64::from(label) * golden).fract();
    let (s, v) = if (label / 7).is_multiple_of(2) {
        (0.80, 0.95)
    } else {
        (0.65, 0.75)
    };
    hsv_to_rgb(hue, s, v)
}

/// Converts hue in [0, 1), saturation and value in [0, 1] to 8-bit RGB.
fn hsv_to_rgb(h: f64, s: f64, v: f64) -> [u8; 3] {
    let h6 = h * 6.0;
    let sector = h6.floor() as i32 % 6;
    let f = h6 - h6.floor();
    let p = v * (1.0 - s);
    let q = v * (1.0 - s * f);
    let t = v * (1.0 - s * (1.0 - f));
    let (r, g, b) = match sector {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    let byte = |c: f64| (c * 255.0).round().clamp(0.0, 255.0) as u8;
    [byte(r), byte(g), byte(b)]
}

/// Checks that there is one label per point.
pub(crate) fn check_label_count(labels: &[u32], points: usize) -> crate::Result<()> {
    if labels.len() == points {
        Ok(())
    } else {
        Err(crate::Error::invalid(
            "labels",
            format!("{} labels for {points} points", labels.len()),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_is_grey_and_others_are_not() {
        assert_eq!(label_colour(0), UNLABELLED_COLOUR);
        for l in 1..1000 {
            let c = label_colour(l);
            assert_ne!(c, UNLABELLED_COLOUR);
            assert!(c.iter().max() != c.iter().min(), "label {l} is grey: {c:?}");
        }
    }

    #[test]
    fn deterministic_and_distinct_for_small_labels() {
        assert_eq!(label_colour(5), label_colour(5));
        let colours: Vec<_> = (0..64).map(label_colour).collect();
        for i in 0..colours.len() {
            for j in i + 1..colours.len() {
                assert_ne!(colours[i], colours[j], "labels {i} and {j}");
            }
        }
    }
}
