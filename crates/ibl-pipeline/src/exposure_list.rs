//! Exposure-time files of `ibl capture merge --times-file` in the formats people have (issue 13):
//!
//! - plain numbers or fractions (`1/250 1/60 0.25`), one per image in order;
//! - two columns `name value` per line, matched to the images by file name (any order): OpenCV's
//!   `list.txt` of its HDR tutorial (`memorial00.png 0.03125`, whose loader does
//!   `times.push_back(1 / val)`: the values are *inverse* seconds) and the `name seconds` lists
//!   such as `exposure_times_seconds.txt`.
//!
//! The unit of a two-column list cannot be told from its numbers, and a wrong guess is a silent
//! factor of up to 10^4, so it comes from `--times-unit` or from the file name (`list.txt`:
//! OpenCV's inverse seconds; a name containing `seconds`: seconds), else the file is refused with
//! a message that says how to choose. `#` starts a comment.

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::{PipelineError, Result};

/// What the numbers of an exposure-time file are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimeUnit {
    /// Exposure times in seconds (`1/250` = 4 ms).
    Seconds,
    /// `1 / seconds`, as OpenCV's `list.txt` holds them (`250` = 4 ms).
    InverseSeconds,
}

impl TimeUnit {
    /// The unit's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TimeUnit::Seconds => "seconds",
            TimeUnit::InverseSeconds => "inverse-seconds",
        }
    }
}

/// A number or a fraction, positive and finite.
fn parse_value(token: &str) -> Option<f64> {
    let v = match token.split_once('/') {
        Some((a, b)) => a.trim().parse::<f64>().ok()? / b.trim().parse::<f64>().ok()?,
        None => token.parse::<f64>().ok()?,
    };
    (v.is_finite() && v > 0.0).then_some(v)
}

/// The unit a two-column file's name implies, if any.
fn unit_from_name(path: &Path) -> Option<TimeUnit> {
    let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
    if name == "list.txt" {
        Some(TimeUnit::InverseSeconds)
    } else if name.contains("seconds") {
        Some(TimeUnit::Seconds)
    } else {
        None
    }
}

/// The exposure time in seconds that `token` of `path` gives in `unit`, positive and finite (the
/// inverse of a subnormal, `1e-310` in a `list.txt`, is infinite and refused like any other bad
/// value); `shown` is how the error message names the token.
fn seconds_of(path: &Path, token: &str, shown: &str, unit: TimeUnit) -> Result<f64> {
    parse_value(token)
        .map(|v| match unit {
            TimeUnit::Seconds => v,
            TimeUnit::InverseSeconds => 1.0 / v,
        })
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| {
            PipelineError::parameter(format!(
                "{}: {shown} is not a positive exposure time",
                path.display()
            ))
        })
}

/// Reads the exposure times of `images` (in their order, seconds) from the text of `path`.
/// `unit` is the caller's `--times-unit`, if given. Returns the times and the unit used.
pub fn parse_times_file(
    path: &Path,
    text: &str,
    images: &[PathBuf],
    unit: Option<TimeUnit>,
) -> Result<(Vec<f64>, TimeUnit)> {
    let shown = path.display();
    let lines: Vec<Vec<&str>> = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .map(|l| {
            l.split(|c: char| c == ',' || c.is_whitespace())
                .filter(|t| !t.is_empty())
                .collect::<Vec<_>>()
        })
        .filter(|t| !t.is_empty())
        .collect();
    let named = lines
        .first()
        .is_some_and(|t| parse_value(t[0]).is_none() && t.len() == 2);
    if !named {
        let unit = unit.unwrap_or(TimeUnit::Seconds);
        let times = lines
            .iter()
            .flatten()
            .map(|token| seconds_of(path, token, &format!("'{token}'"), unit))
            .collect::<Result<Vec<_>>>()?;
        return Ok((times, unit));
    }
    let unit = unit.or_else(|| unit_from_name(path)).ok_or_else(|| {
        PipelineError::parameter(format!(
            "{shown}: a `name value` list; say what the values are with --times-unit seconds \
             or --times-unit inverse-seconds (OpenCV's list.txt holds 1/seconds)"
        ))
    })?;
    let mut entries: Vec<(String, f64)> = Vec::new();
    for (k, tokens) in lines.iter().enumerate() {
        let (Some(name), Some(value), 2) = (tokens.first(), tokens.get(1), tokens.len()) else {
            return Err(PipelineError::parameter(format!(
                "{shown}: line {} of the `name value` list has {} fields",
                k + 1,
                tokens.len()
            )));
        };
        let t = seconds_of(path, value, &format!("'{value}' ({name})"), unit)?;
        entries.push((name.to_string(), t));
    }
    let mut times = Vec::with_capacity(images.len());
    for image in images {
        let base = image
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let found = entries
            .iter()
            .find(|(name, _)| {
                Path::new(name)
                    .file_name()
                    .is_some_and(|n| n.to_string_lossy() == base)
            })
            .ok_or_else(|| {
                PipelineError::parameter(format!("{shown}: lists no exposure time for {base}"))
            })?;
        times.push(found.1);
    }
    Ok((times, unit))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn images(names: &[&str]) -> Vec<PathBuf> {
        names
            .iter()
            .map(|n| PathBuf::from("photos").join(n))
            .collect()
    }

    #[test]
    fn opencv_list_txt_holds_inverse_seconds_matched_by_name() {
        // OpenCV's samples/data/exposures/list.txt, in its format (values 1/seconds).
        let text = "memorial00.png 0.03125\nmemorial01.png 0.0625\nmemorial02.png 0.125\n";
        let (t, unit) = parse_times_file(
            Path::new("dir/list.txt"),
            text,
            &images(&["memorial02.png", "memorial00.png"]),
            None,
        )
        .unwrap();
        assert_eq!(unit, TimeUnit::InverseSeconds);
        // Exact: 1 / 2^-k is a power of two.
        assert_eq!(t, vec![8.0, 32.0]);
    }

    #[test]
    fn two_column_seconds_lists_and_plain_lists() {
        let text = "# name seconds\na.jpg 1/250\nb.jpg 0.25\n";
        let (t, _) = parse_times_file(
            Path::new("exposure_times_seconds.txt"),
            text,
            &images(&["a.jpg", "b.jpg"]),
            None,
        )
        .unwrap();
        assert_eq!(t, vec![1.0 / 250.0, 0.25]);
        let (t, unit) = parse_times_file(
            Path::new("t.txt"),
            "1/250, 1/60\n",
            &images(&["a", "b"]),
            None,
        )
        .unwrap();
        assert_eq!(
            (t, unit),
            (vec![1.0 / 250.0, 1.0 / 60.0], TimeUnit::Seconds)
        );
    }

    #[test]
    fn an_inverse_time_too_small_to_invert_is_refused() {
        // Found while writing the `exposure_times` fuzz target: 1 / 1e-310 is infinite, and
        // was returned as an exposure time.
        for (text, imgs) in [("a.jpg 1e-310\n", &["a.jpg"][..]), ("1e-310\n", &["a"][..])] {
            let e = parse_times_file(
                Path::new("list.txt"),
                text,
                &images(imgs),
                Some(TimeUnit::InverseSeconds),
            );
            let message = e.unwrap_err().to_string();
            assert!(
                message.contains("not a positive exposure time"),
                "{message}"
            );
        }
    }

    #[test]
    fn an_unknown_unit_or_a_missing_image_is_refused() {
        let text = "a.jpg 250\n";
        let e = parse_times_file(Path::new("t.txt"), text, &images(&["a.jpg"]), None);
        assert!(e.unwrap_err().to_string().contains("--times-unit"));
        let e = parse_times_file(
            Path::new("t.txt"),
            text,
            &images(&["b.jpg"]),
            Some(TimeUnit::InverseSeconds),
        );
        assert!(e.unwrap_err().to_string().contains("b.jpg"));
        let (t, _) = parse_times_file(
            Path::new("t.txt"),
            text,
            &images(&["a.jpg"]),
            Some(TimeUnit::InverseSeconds),
        )
        .unwrap();
        assert_eq!(t, vec![1.0 / 250.0]);
    }
}
