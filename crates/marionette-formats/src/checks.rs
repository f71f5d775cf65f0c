//! Checks of the numbers documents hold: each error names the field (`characters[0].placement.scale`).

/// Every value finite.
pub fn finite(at: &str, values: &[f32]) -> Result<(), String> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("{at}: expected a finite number, found {v}")),
        None => Ok(()),
    }
}

/// A positive finite number.
pub fn positive(at: &str, value: f32) -> Result<(), String> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(format!("{at}: expected a positive finite number, found {value}"))
    }
}
