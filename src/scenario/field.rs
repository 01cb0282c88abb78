//! Checks of single values of a scenario file, each naming the field it checks: the
//! scenario's validation (`scenario::validate`) and each terrain primitive's
//! (`terrain::PrimitiveKind::validate`) are written with them, so every bad value is
//! reported the same way, as the dotted path of its field and what is wrong with it.

/// A value out of range: the dotted path of its field (`terrain[2].size`) and the reason.
pub(crate) type FieldError = (String, String);

/// `v` must be a finite number.
pub(crate) fn finite(field: &str, v: f64) -> Result<(), FieldError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err((field.to_owned(), format!("{v} is not a finite number")))
    }
}

/// `v` must be a finite number above zero.
pub(crate) fn positive(field: &str, v: f64) -> Result<(), FieldError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err((field.to_owned(), format!("{v} must be a finite number > 0")))
    }
}

/// `v` must be a finite number, zero or above.
pub(crate) fn non_negative(field: &str, v: f64) -> Result<(), FieldError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err((field.to_owned(), format!("{v} must be a finite number >= 0")))
    }
}
