//! IES LM-63 photometric files (`.ies`), the 1986, 1991, 1995, 2002 and 2019 editions.
//!
//! Layout: an identification line (`IESNA91`, `IESNA:LM-63-1995`, `IESNA:LM-63-2002`,
//! `IES:LM-63-2019`; none in 1986 files), header lines up to `TILT=` (`[KEYWORD] value`
//! lines, `[MORE]` continuing the previous keyword, and in 1986 files free text), then numbers
//! separated by blanks or commas, across lines as they come:
//!
//! 1. lamps, lumens per lamp (`-1`: absolute photometry), candela multiplier, vertical and
//!    horizontal angle counts, photometric type (1 = C, 2 = B, 3 = A), units of the opening
//!    (1 feet, 2 metres), width, length, height of the opening;
//! 2. ballast factor, a second factor (the ballast-lamp photometric factor up to 1995, "future
//!    use" in 2002, the file generation type in 2019), input watts;
//! 3. the vertical angles, the horizontal angles, then the candela values plane by plane
//!    (all vertical angles of the first horizontal angle, then the next plane, ...).
//!
//! `TILT=INCLUDE` puts the lamp's tilt table between `TILT=` and those numbers (geometry, pair
//! count, angles, multiplying factors): it is read and kept ([`Tilt`]); the candela table stays as
//! measured (lamp untilted), since which factor applies depends on how the luminaire is mounted.
//! `TILT=<file>` names a separate file, which is refused: this reader opens one file only.
//!
//! Type C is read fully: vertical angles from the nadir, horizontal angles counterclockwise seen
//! from above, the light frame of [`ibl_light::goniometric`] as it stands. Types B and A
//! (floodlight and automotive photometry, whose polar axis is horizontal) are refused with a
//! clear error rather than guessed at. Horizontal symmetry (LM-63-2002, the horizontal angles):
//! one angle, 0 to 90, 0 to 180, 90 to 270, or 0 to more than 180 (at most 360); any other range
//! is refused ([`super::symmetry`] expands them).
//!
//! Candela: `value x multiplier x ballast factor`, times the ballast-lamp photometric factor in
//! files up to 1995 (where that field is one). Relative photometry states the lamps' lumens
//! (`lamps x lumens per lamp`, with the same factors), which the table integrates to only after
//! the luminaire's light output ratio; LM-63 has no field for that ratio, so it is taken from a
//! header line `light output ratio: 0.59` (any case; a `%` sign means percent) where a writer adds
//! one, as an ERCO file among the bundled ones does ([`IesFile::light_output_ratio`]).

use ibl_light::CandelaTable;

use super::limits::PhotometryLimits;
use super::stated::StatedFlux;
use super::symmetry::{self, Symmetry, near};
use super::text::{self, Values};
use crate::error::DecodeError;

/// The LM-63 edition a file names on its first line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IesVersion {
    /// LM-63-1986: no identification line.
    Lm63_1986,
    /// LM-63-1991: `IESNA91`.
    Lm63_1991,
    /// LM-63-1995: `IESNA:LM-63-1995`.
    Lm63_1995,
    /// LM-63-2002: `IESNA:LM-63-2002`.
    Lm63_2002,
    /// LM-63-2019: `IES:LM-63-2019` (or `IESNA:LM-63-2019`).
    Lm63_2019,
}

impl IesVersion {
    /// `"LM-63-1986"` and so on.
    pub fn name(self) -> &'static str {
        match self {
            IesVersion::Lm63_1986 => "LM-63-1986",
            IesVersion::Lm63_1991 => "LM-63-1991",
            IesVersion::Lm63_1995 => "LM-63-1995",
            IesVersion::Lm63_2002 => "LM-63-2002",
            IesVersion::Lm63_2019 => "LM-63-2019",
        }
    }

    /// Whether the second factor of the ballast line multiplies the candela values (it is the
    /// ballast-lamp photometric factor up to 1995).
    fn second_factor_multiplies(self) -> bool {
        matches!(
            self,
            IesVersion::Lm63_1986 | IesVersion::Lm63_1991 | IesVersion::Lm63_1995
        )
    }

    /// The version named by a first line, `Ok(None)` for a 1986 file (no identification).
    fn of_first_line(line: &str) -> Result<Option<IesVersion>, DecodeError> {
        let id = line.trim().to_ascii_uppercase();
        let known = [
            ("IESNA91", IesVersion::Lm63_1991),
            ("IESNA:LM-63-1991", IesVersion::Lm63_1991),
            ("IESNA:LM-63-1995", IesVersion::Lm63_1995),
            ("IESNA:LM-63-2002", IesVersion::Lm63_2002),
            ("IESNA:LM-63-2019", IesVersion::Lm63_2019),
            ("IES:LM-63-2019", IesVersion::Lm63_2019),
        ];
        if let Some((_, v)) = known.iter().find(|(tag, _)| id.starts_with(tag)) {
            return Ok(Some(*v));
        }
        if id.starts_with("IESNA") || id.starts_with("IES:LM-63") {
            return Err(DecodeError::Unsupported(format!(
                "line 1: {:?} names no LM-63 edition this reader knows (1986 without such a line, \
                 1991, 1995, 2002, 2019)",
                line.trim()
            )));
        }
        Ok(None)
    }
}

/// The tilt section of a file.
#[derive(Clone, Debug, PartialEq)]
pub enum Tilt {
    /// `TILT=NONE`: the lamp's output does not depend on its tilt.
    None,
    /// `TILT=INCLUDE`: multiplying factors of the lamp's output by tilt angle.
    Include {
        /// Lamp-to-luminaire geometry, 1 to 3 (LM-63: vertical base-up or base-down, horizontal
        /// fixed, horizontal turning with the luminaire).
        geometry: u8,
        /// Tilt angles, degrees.
        angles_deg: Vec<f64>,
        /// The lamp output's factor at each angle.
        factors: Vec<f64>,
    },
}

/// The unit of the luminous opening's dimensions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpeningUnits {
    /// Feet (code 1).
    Feet,
    /// Metres (code 2).
    Metres,
}

/// An IES LM-63 file as read: its header, its numbers and the expanded candela table.
#[derive(Clone, Debug, PartialEq)]
pub struct IesFile {
    /// The edition named on the first line.
    pub version: IesVersion,
    /// `[KEYWORD] value` lines in order, keywords upper case, `[MORE]` lines joined to the
    /// previous value with a newline.
    pub keywords: Vec<(String, String)>,
    /// Header lines that are not keywords (all of them in a 1986 file), trimmed.
    pub text_lines: Vec<String>,
    /// The tilt section.
    pub tilt: Tilt,
    /// Number of lamps.
    pub lamps: usize,
    /// Rated lumens per lamp; `None` for absolute photometry (`-1` in the file).
    pub lumens_per_lamp: Option<f64>,
    /// The candela multiplier.
    pub candela_multiplier: f64,
    /// Unit of [`IesFile::opening`].
    pub units: OpeningUnits,
    /// Width, length and height of the luminous opening (LM-63's sign conventions for round
    /// and point openings kept as written).
    pub opening: [f64; 3],
    /// The ballast factor.
    pub ballast_factor: f64,
    /// The ballast line's second field: the ballast-lamp photometric factor (up to 1995),
    /// "future use" (2002) or the file generation type (2019).
    pub second_factor: f64,
    /// Input watts.
    pub input_watts: f64,
    /// The horizontal symmetry the angles declare.
    pub symmetry: Symmetry,
    /// Luminous intensity, cd, expanded to the full turn (values times [`IesFile::candela_scale`]).
    pub table: CandelaTable,
}

impl IesFile {
    /// The value of the first `[key]` line (upper-case key), if any.
    pub fn keyword(&self, key: &str) -> Option<&str> {
        self.keywords
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The factor from the file's values to candela: multiplier x ballast factor (x the
    /// ballast-lamp photometric factor up to 1995).
    pub fn candela_scale(&self) -> f64 {
        self.candela_multiplier * self.operating_factor()
    }

    /// Ballast factor, times the ballast-lamp photometric factor up to 1995.
    fn operating_factor(&self) -> f64 {
        operating_factor(self.version, self.ballast_factor, self.second_factor)
    }

    /// The luminaire's light output ratio (a fraction in `0..=1`) where a header line states it
    /// as `light output ratio: X` (module doc); `None` otherwise.
    pub fn light_output_ratio(&self) -> Option<f64> {
        let lines = self
            .text_lines
            .iter()
            .map(String::as_str)
            .chain(self.keywords.iter().map(|(_, v)| v.as_str()));
        lines.filter_map(ratio_in).next()
    }

    /// The name: the `[LUMINAIRE]` keyword, else `[LUMCAT]`, else the first header text line.
    pub fn name(&self) -> &str {
        self.keyword("LUMINAIRE")
            .or_else(|| self.keyword("LUMCAT"))
            .or_else(|| {
                self.text_lines
                    .iter()
                    .find(|l| !l.is_empty())
                    .map(String::as_str)
            })
            .unwrap_or("")
    }

    /// What the file says the table's flux is (see [`StatedFlux`]).
    pub fn stated_flux(&self) -> StatedFlux {
        match self.lumens_per_lamp {
            None => StatedFlux::Absolute,
            Some(per_lamp) => {
                let lamp_lumens = self.lamps as f64 * per_lamp * self.operating_factor();
                match self.light_output_ratio() {
                    Some(light_output_ratio) => StatedFlux::LampsAndLor {
                        lamp_lumens,
                        light_output_ratio,
                    },
                    None => StatedFlux::Lamps { lamp_lumens },
                }
            }
        }
    }
}

/// The ballast factor, times the second factor where it is the ballast-lamp photometric factor.
fn operating_factor(version: IesVersion, ballast_factor: f64, second_factor: f64) -> f64 {
    if version.second_factor_multiplies() {
        ballast_factor * second_factor
    } else {
        ballast_factor
    }
}

/// The ratio in a `light output ratio: X` line (`X` a fraction, or a percentage with `%`).
fn ratio_in(line: &str) -> Option<f64> {
    const TAG: &str = "light output ratio";
    let lower = line.to_ascii_lowercase();
    let after = lower[lower.find(TAG)? + TAG.len()..].trim_start();
    let after = after.strip_prefix([':', '='])?.trim_start();
    let end = after
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(after.len());
    let mut ratio = text::number(&after[..end])?;
    if after[end..].trim_start().starts_with('%') {
        ratio /= 100.0;
    }
    (ratio > 0.0 && ratio <= 1.0).then_some(ratio)
}

/// Whether a header line is the `TILT=` line.
fn is_tilt_line(line: &str) -> bool {
    let t = line.trim_start();
    t.get(..4).is_some_and(|k| k.eq_ignore_ascii_case("TILT"))
        && t[4..].trim_start().starts_with('=')
}

/// Reads an IES file from its bytes (no path: see [`super::read_photometry`]).
pub fn decode(bytes: &[u8], limits: &PhotometryLimits) -> Result<IesFile, DecodeError> {
    if bytes.len() as u64 > limits.max_bytes {
        return Err(DecodeError::Limits(format!(
            "{} bytes, over the limit of {}",
            bytes.len(),
            limits.max_bytes
        )));
    }
    let text = text::decode(bytes);
    let lines = text::lines(&text);
    let Some(&(_, first)) = lines.first() else {
        return Err(DecodeError::invalid("empty file"));
    };
    let identified = IesVersion::of_first_line(first)?;
    let version = identified.unwrap_or(IesVersion::Lm63_1986);
    let header_start = usize::from(identified.is_some());
    let Some(tilt_at) = lines.iter().position(|(_, l)| is_tilt_line(l)) else {
        return Err(DecodeError::invalid(
            "no TILT= line: an IES LM-63 file has one between its header and its numbers",
        ));
    };
    let (keywords, text_lines) = header(&lines[header_start.min(tilt_at)..tilt_at]);
    let (tilt_line, tilt_text) = lines[tilt_at];
    let tilt_value = tilt_text
        .trim_start()
        .split_once('=')
        .map_or("", |(_, v)| v.trim());
    let mut values = Values::new(&lines[tilt_at + 1..], &[',']);
    let tilt = if tilt_value.eq_ignore_ascii_case("NONE") {
        Tilt::None
    } else if tilt_value.eq_ignore_ascii_case("INCLUDE") {
        tilt_table(&mut values, limits)?
    } else {
        return Err(DecodeError::Unsupported(format!(
            "line {tilt_line}: TILT={tilt_value} names a separate tilt file, which is not read \
             (use TILT=INCLUDE with the tilt data in the file, or TILT=NONE)"
        )));
    };
    let lamps = values.count("the number of lamps", 1, 1_000_000)?;
    let (lumens, line) = values.number("the lumens per lamp", false)?;
    let lumens_per_lamp = if lumens == -1.0 {
        None
    } else if lumens > 0.0 {
        Some(lumens)
    } else {
        return Err(DecodeError::invalid(format!(
            "line {line}: lumens per lamp is {lumens} (positive, or -1 for absolute photometry)"
        )));
    };
    let candela_multiplier = positive(&mut values, "the candela multiplier")?;
    let n_vertical = values.count("the number of vertical angles", 2, limits.max_angles)?;
    let n_horizontal = values.count("the number of horizontal angles", 1, limits.max_angles)?;
    let (kind, line) = values.number("the photometric type", false)?;
    match kind {
        1.0 => {}
        2.0 | 3.0 => {
            return Err(DecodeError::Unsupported(format!(
                "line {line}: photometric type {kind} (type {}, whose polar axis is horizontal) \
                 is not read; only type C (1) is",
                if kind == 2.0 { "B" } else { "A" }
            )));
        }
        _ => {
            return Err(DecodeError::invalid(format!(
                "line {line}: photometric type is {kind} (1 = C, 2 = B, 3 = A)"
            )));
        }
    }
    let (code, line) = values.number("the units type", false)?;
    let units = match code {
        1.0 => OpeningUnits::Feet,
        2.0 => OpeningUnits::Metres,
        _ => {
            return Err(DecodeError::invalid(format!(
                "line {line}: units type is {code} (1 = feet, 2 = metres)"
            )));
        }
    };
    let mut opening = [0.0; 3];
    for (o, what) in opening.iter_mut().zip(["width", "length", "height"]) {
        *o = values.number(&format!("the opening {what}"), false)?.0;
    }
    let ballast_factor = positive(&mut values, "the ballast factor")?;
    let (second_factor, line) = values.number("the ballast line's second factor", false)?;
    if version.second_factor_multiplies() && second_factor <= 0.0 {
        return Err(DecodeError::invalid(format!(
            "line {line}: the ballast-lamp photometric factor is {second_factor} (must be positive)"
        )));
    }
    let input_watts = values.number("the input watts", false)?.0;

    let n_values = n_vertical
        .checked_mul(n_horizontal)
        .filter(|&n| n <= limits.max_values)
        .ok_or_else(|| {
            DecodeError::Limits(format!(
                "{n_vertical} x {n_horizontal} candela values, over the limit of {}",
                limits.max_values
            ))
        })?;
    let needed = n_vertical + n_horizontal + n_values;
    if values.remaining() < needed {
        return Err(DecodeError::Limits(format!(
            "{n_vertical} vertical and {n_horizontal} horizontal angles need {needed} more \
             values, and the file holds only {}",
            values.remaining()
        )));
    }
    let vertical = values.angles("vertical", n_vertical, 180.0, false)?;
    let horizontal = values.angles("horizontal", n_horizontal, 360.0, false)?;
    let mut stored = Vec::with_capacity(n_values);
    for h in &horizontal {
        for v in &vertical {
            let what = format!("the candela value at horizontal angle {h} and vertical angle {v}");
            let (cd, line) = values.number(&what, false)?;
            if cd < 0.0 {
                return Err(DecodeError::invalid(format!(
                    "line {line}: {what} is negative ({cd})"
                )));
            }
            stored.push(cd as f32);
        }
    }
    if let Some(extra) = values
        .rest()
        .iter()
        .find(|t| !(t.text.trim_matches('\u{1a}').is_empty() || t.text.eq_ignore_ascii_case("END")))
    {
        return Err(DecodeError::invalid(format!(
            "line {}: {:?} follows the {n_vertical} x {n_horizontal} candela values",
            extra.line, extra.text
        )));
    }
    let symmetry = horizontal_symmetry(&horizontal)?;
    let scale = candela_multiplier * operating_factor(version, ballast_factor, second_factor);
    let (h, cd) = symmetry::expand(symmetry, &horizontal, &stored, n_vertical, scale);
    let v = vertical.iter().map(|&a| a as f32).collect();
    let table = CandelaTable::new(v, h, cd).map_err(|e| DecodeError::invalid(e.to_string()))?;
    Ok(IesFile {
        version,
        keywords,
        text_lines,
        tilt,
        lamps,
        lumens_per_lamp,
        candela_multiplier,
        units,
        opening,
        ballast_factor,
        second_factor,
        input_watts,
        symmetry,
        table,
    })
}

/// Splits header lines into keywords and free text (module doc).
fn header(lines: &[(usize, &str)]) -> (Vec<(String, String)>, Vec<String>) {
    let mut keywords: Vec<(String, String)> = Vec::new();
    let mut text_lines = Vec::new();
    for &(_, line) in lines {
        let t = line.trim();
        let keyword = t
            .strip_prefix('[')
            .and_then(|r| r.split_once(']'))
            .map(|(k, v)| (k.trim().to_ascii_uppercase(), v.trim().to_string()));
        match keyword {
            Some((k, v)) if k == "MORE" && !keywords.is_empty() => {
                if let Some(last) = keywords.last_mut() {
                    last.1.push('\n');
                    last.1.push_str(&v);
                }
            }
            Some(kv) => keywords.push(kv),
            None => text_lines.push(t.to_string()),
        }
    }
    (keywords, text_lines)
}

/// The `TILT=INCLUDE` block: geometry, pair count, angles, factors.
fn tilt_table(values: &mut Values<'_>, limits: &PhotometryLimits) -> Result<Tilt, DecodeError> {
    let geometry = values.count("the TILT lamp-to-luminaire geometry", 1, 3)? as u8;
    let pairs = values.count("the number of TILT angles", 1, limits.max_angles)?;
    if values.remaining() < 2 * pairs {
        return Err(DecodeError::Limits(format!(
            "{pairs} TILT angles and factors need {} values, and the file holds only {}",
            2 * pairs,
            values.remaining()
        )));
    }
    let angles_deg = (0..pairs)
        .map(|k| {
            values
                .number(&format!("TILT angle {}", k + 1), false)
                .map(|v| v.0)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let factors = (0..pairs)
        .map(|k| {
            values
                .number(&format!("TILT factor {}", k + 1), false)
                .map(|v| v.0)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Tilt::Include {
        geometry,
        angles_deg,
        factors,
    })
}

/// A positive number (`what` names the field).
fn positive(values: &mut Values<'_>, what: &str) -> Result<f64, DecodeError> {
    let (v, line) = values.number(what, false)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(DecodeError::invalid(format!(
            "line {line}: {what} is {v} (must be positive)"
        )))
    }
}

/// The symmetry the horizontal angles of a type C file declare (LM-63-2002).
fn horizontal_symmetry(h: &[f64]) -> Result<Symmetry, DecodeError> {
    let (first, last) = (h[0], h[h.len() - 1]);
    Ok(if h.len() == 1 {
        Symmetry::Axial
    } else if near(first, 0.0) && near(last, 90.0) {
        Symmetry::Quadrant
    } else if near(first, 0.0) && near(last, 180.0) {
        Symmetry::PlaneC0C180
    } else if near(first, 90.0) && near(last, 270.0) {
        Symmetry::PlaneC90C270
    } else if near(first, 0.0) && last > 180.0 {
        Symmetry::None
    } else {
        return Err(DecodeError::invalid(format!(
            "horizontal angles run from {first} to {last}: type C needs one angle, 0 to 90, 0 to \
             180, 90 to 270, or 0 to more than 180 (at most 360)"
        )));
    })
}
