//! Text as the grader echoes it back: values from files cut short, numbers
//! to five significant digits.

/// At most 60 characters of `text`, with "…" where it was cut.
pub fn shorten(text: &str) -> String {
    const LIMIT: usize = 60;
    if text.chars().count() <= LIMIT {
        text.to_owned()
    } else {
        text.chars().take(LIMIT).collect::<String>() + "…"
    }
}

/// `x` to 5 significant digits, as `glint explain` prints its numbers.
pub fn number(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let scale = 10f64.powi(4 - x.abs().log10().floor() as i32);
    let rounded = (x * scale).round() / scale;
    // The rounding can leave binary noise: print the shortest form of the
    // f32 nearest it where that is as close, else the f64.
    let short = rounded as f32;
    if f64::from(short) == rounded || ((f64::from(short) - rounded) / rounded).abs() < 1e-9 {
        short.to_string()
    } else {
        rounded.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_shown_to_five_significant_digits() {
        assert_eq!(number(0.000837051234), "0.00083705");
        assert_eq!(number(0.5), "0.5");
        assert_eq!(number(123456.0), "123460");
        assert_eq!(number(0.0), "0");
    }
}
