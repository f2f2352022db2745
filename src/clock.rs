//! Machine time as the page writes it, everywhere: hours, minutes and seconds (`h:mm:ss`), the
//! unit a shop reads off a controller; the animation's running clock adds tenths.

/// `seconds` as `h:mm:ss`, rounded to the second; "—" when there is no time.
pub fn hms(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "—".into();
    }
    let total = seconds.max(0.0).round() as u64;
    format!("{}:{:02}:{:02}", total / 3600, total / 60 % 60, total % 60)
}

/// `seconds` as `h:mm:ss.s`, rounded to the tenth: the animation's clock, which moves in
/// steps shorter than a second.
pub fn hms_tenths(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "—".into();
    }
    let tenths = (seconds.max(0.0) * 10.0).round() as u64;
    let whole = tenths / 10;
    format!(
        "{}:{:02}:{:02}.{}",
        whole / 3600,
        whole / 60 % 60,
        whole % 60,
        tenths % 10
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hours_minutes_seconds() {
        assert_eq!(hms(0.0), "0:00:00");
        assert_eq!(hms(7463.8), "2:04:24");
        assert_eq!(hms(59.5), "0:01:00");
        assert_eq!(hms(f64::NAN), "—");
        assert_eq!(hms(-3.0), "0:00:00");
        assert_eq!(hms_tenths(0.0), "0:00:00.0");
        assert_eq!(hms_tenths(75.34), "0:01:15.3");
        assert_eq!(hms_tenths(7463.84), "2:04:23.8");
        assert_eq!(hms_tenths(59.96), "0:01:00.0");
    }
}
