//! EULUMDAT files (`.ldt`, Stockmar 1990 and 1998): one field per line, in a fixed order.
//!
//! Lines 1 to 25: identification, `Ityp`, `Isym` (symmetry, 0 to 4), `Nc` (C planes in the full
//! turn), `Dc`, `Ng` (intensities per plane), `Dg`, report number, luminaire name and number, file
//! name, date and user, the luminaire's and the luminous area's dimensions (mm, lines 13 to 21),
//! the downward flux fraction (%), the light output ratio `LORL` (%), the conversion factor for
//! luminous intensities, the tilt during measurement; line 26 the number `n` of lamp sets, then 6
//! lines per set (number of lamps, type, total flux of the set in lm, colour, colour rendering,
//! watts); then 10 direct ratios; then the `Nc` C angles, the `Ng` gamma angles and the stored
//! planes' intensities in cd per 1000 lamp lumens, plane by plane. Numbers may use a decimal
//! comma. The angle and intensity section is read value by value across lines, so writers that
//! put several values on a line are read too.
//!
//! The stored planes by `Isym` ([`super::symmetry`]): 0 all `Nc`; 1 one; 2 the `Nc / 2 + 1`
//! planes C0 to C180; 3 the `Nc / 2 + 1` planes C90 to C270 (the C angles from index `Nc / 4`
//! on); 4 the `Nc / 4 + 1` planes C0 to C90. The C angles at the ends of a stored range must be
//! the range's own (0, 90, 180, 270).
//!
//! Candela: `value x (flux of lamp set 1) / 1000 x conversion factor`. The table should then
//! integrate to the luminaire's flux, `LORL x` that lamp flux, which is what
//! [`LdtFile::stated_flux`] states (files that mark absolute photometry with a negative number of
//! lamps put the luminaire's own flux and `LORL = 100` there, so the same comparison holds).

use ibl_light::CandelaTable;

use super::limits::PhotometryLimits;
use super::stated::StatedFlux;
use super::symmetry::{self, Symmetry, near};
use super::text::{self, Values};
use crate::error::DecodeError;

/// One lamp set (lines 26a to 26f).
#[derive(Clone, Debug, PartialEq)]
pub struct LampSet {
    /// Number of lamps (negative in files that mark absolute photometry that way).
    pub lamps: i64,
    /// Type of lamps.
    pub kind: String,
    /// Total luminous flux of the set's lamps, lm.
    pub lumens: f64,
    /// Colour appearance or temperature, as written.
    pub colour: String,
    /// Colour rendering group or index, as written.
    pub colour_rendering: String,
    /// Wattage including ballast, W.
    pub watts: f64,
}

/// An EULUMDAT file as read: its fields and the expanded candela table.
#[derive(Clone, Debug, PartialEq)]
pub struct LdtFile {
    /// Line 1: company, databank, version.
    pub identification: String,
    /// `Ityp` (line 2): 0 point source without symmetry, 1 symmetric about the vertical axis, 2
    /// linear luminaire, 3 point source with other symmetry.
    pub type_indicator: u8,
    /// `Isym` (line 3) as a symmetry.
    pub symmetry: Symmetry,
    /// `Nc` (line 4): C planes in the full turn.
    pub c_planes: usize,
    /// `Dc` (line 5): their spacing, degrees (0 when not equidistant).
    pub c_spacing_deg: f64,
    /// `Ng` (line 6): intensities per plane.
    pub gamma_count: usize,
    /// `Dg` (line 7): their spacing, degrees (0 when not equidistant).
    pub gamma_spacing_deg: f64,
    /// Line 8: measurement report number.
    pub report_number: String,
    /// Line 9: luminaire name.
    pub luminaire_name: String,
    /// Line 10: luminaire number.
    pub luminaire_number: String,
    /// Line 11: file name.
    pub file_name: String,
    /// Line 12: date and user.
    pub date_user: String,
    /// Lines 13 to 15: luminaire length (or diameter), width (0: round), height, mm.
    pub luminaire_mm: [f64; 3],
    /// Lines 16, 17: luminous area length (or diameter), width (0: round), mm.
    pub luminous_area_mm: [f64; 2],
    /// Lines 18 to 21: height of the luminous area at C0, C90, C180, C270, mm.
    pub luminous_heights_mm: [f64; 4],
    /// Line 22: downward flux fraction, percent.
    pub downward_flux_fraction_percent: f64,
    /// Line 23: light output ratio of the luminaire (`LORL`), percent.
    pub light_output_ratio_percent: f64,
    /// Line 24: conversion factor for luminous intensities.
    pub intensity_factor: f64,
    /// Line 25: tilt of the luminaire during measurement, degrees.
    pub tilt_deg: f64,
    /// Lines 26a to 26f per set (at least one).
    pub lamp_sets: Vec<LampSet>,
    /// Line 27: direct ratios for the room indices 0.6 to 5.
    pub direct_ratios: [f64; 10],
    /// Luminous intensity, cd, expanded to the full turn (values times [`LdtFile::candela_scale`]).
    pub table: CandelaTable,
}

impl LdtFile {
    /// The factor from the file's cd/klm to cd: the first lamp set's flux / 1000 times the
    /// conversion factor.
    pub fn candela_scale(&self) -> f64 {
        self.lamp_sets[0].lumens / 1000.0 * self.intensity_factor
    }

    /// The first lamp set's flux and `LORL` (see the module doc).
    pub fn stated_flux(&self) -> StatedFlux {
        StatedFlux::LampsAndLor {
            lamp_lumens: self.lamp_sets[0].lumens,
            light_output_ratio: self.light_output_ratio_percent / 100.0,
        }
    }
}

/// The line cursor of the fixed part: each field one line.
struct Fields<'a> {
    lines: &'a [(usize, &'a str)],
    next: usize,
}

impl<'a> Fields<'a> {
    /// The next line's text; `what` names the field in the error.
    fn text(&mut self, what: &str) -> Result<&'a str, DecodeError> {
        let Some(&(_, t)) = self.lines.get(self.next) else {
            return Err(DecodeError::invalid(format!(
                "the file ends after line {} before line {} ({what})",
                self.lines.len(),
                self.next + 1
            )));
        };
        self.next += 1;
        Ok(t.trim())
    }

    /// The next line as a finite number (decimal comma allowed).
    fn number(&mut self, what: &str) -> Result<f64, DecodeError> {
        let t = self.text(what)?;
        text::number(&t.replace(',', ".")).ok_or_else(|| {
            DecodeError::invalid(format!(
                "line {} ({what}): {t:?} is not a finite number",
                self.next
            ))
        })
    }

    /// The next line as a whole number in `min..=max` (over `max`: a limits error).
    fn count(&mut self, what: &str, min: usize, max: usize) -> Result<usize, DecodeError> {
        let v = self.number(what)?;
        text::whole(v, self.next, what, min, max)
    }

    /// The next line as one of the codes `0..=max`.
    fn code(&mut self, what: &str, max: u8) -> Result<u8, DecodeError> {
        let v = self.number(what)?;
        if v.fract() == 0.0 && (0.0..=f64::from(max)).contains(&v) {
            Ok(v as u8)
        } else {
            Err(DecodeError::invalid(format!(
                "line {} ({what}): {v} is not one of the codes 0 to {max}",
                self.next
            )))
        }
    }
}

/// Reads an EULUMDAT file from its bytes (no path: see [`super::read_photometry`]).
pub fn decode(bytes: &[u8], limits: &PhotometryLimits) -> Result<LdtFile, DecodeError> {
    if bytes.len() as u64 > limits.max_bytes {
        return Err(DecodeError::Limits(format!(
            "{} bytes, over the limit of {}",
            bytes.len(),
            limits.max_bytes
        )));
    }
    let text = text::decode(bytes);
    let lines = text::lines(&text);
    if lines.is_empty() {
        return Err(DecodeError::invalid("empty file"));
    }
    let mut f = Fields {
        lines: &lines,
        next: 0,
    };
    let identification = f.text("identification")?.to_string();
    let type_indicator = f.code("Ityp, the type indicator", 3)?;
    let symmetry = match f.code("Isym, the symmetry indicator", 4)? {
        0 => Symmetry::None,
        1 => Symmetry::Axial,
        2 => Symmetry::PlaneC0C180,
        3 => Symmetry::PlaneC90C270,
        _ => Symmetry::Quadrant,
    };
    let c_planes = f.count("Nc, the number of C planes", 0, limits.max_angles)?;
    let c_spacing_deg = f.number("Dc, the C plane spacing")?;
    let gamma_count = f.count("Ng, the intensities per C plane", 2, limits.max_angles)?;
    let gamma_spacing_deg = f.number("Dg, the gamma spacing")?;
    let report_number = f.text("measurement report number")?.to_string();
    let luminaire_name = f.text("luminaire name")?.to_string();
    let luminaire_number = f.text("luminaire number")?.to_string();
    let file_name = f.text("file name")?.to_string();
    let date_user = f.text("date/user")?.to_string();
    let mut luminaire_mm = [0.0; 3];
    for (v, what) in
        luminaire_mm
            .iter_mut()
            .zip(["luminaire length", "luminaire width", "luminaire height"])
    {
        *v = f.number(what)?;
    }
    let mut luminous_area_mm = [0.0; 2];
    for (v, what) in luminous_area_mm
        .iter_mut()
        .zip(["luminous area length", "luminous area width"])
    {
        *v = f.number(what)?;
    }
    let mut luminous_heights_mm = [0.0; 4];
    for (v, what) in luminous_heights_mm.iter_mut().zip([
        "luminous height at C0",
        "luminous height at C90",
        "luminous height at C180",
        "luminous height at C270",
    ]) {
        *v = f.number(what)?;
    }
    let downward_flux_fraction_percent = f.number("DFF, the downward flux fraction")?;
    let light_output_ratio_percent = f.number("LORL, the light output ratio")?;
    let intensity_factor = f.number("the conversion factor for luminous intensities")?;
    if intensity_factor <= 0.0 {
        return Err(DecodeError::invalid(format!(
            "line 24: the conversion factor for luminous intensities is {intensity_factor} \
             (must be positive)"
        )));
    }
    let tilt_deg = f.number("the tilt during measurement")?;
    let sets = f.count("n, the number of lamp sets", 1, lines.len() / 6)?;
    let mut lamp_sets = Vec::with_capacity(sets);
    let mut first_flux_line = 0;
    for k in 1..=sets {
        let lamps = f.number(&format!("number of lamps of set {k}"))?;
        if lamps.fract() != 0.0 || lamps.abs() > 1e9 {
            return Err(DecodeError::invalid(format!(
                "line {}: the number of lamps of set {k} is {lamps}, not a whole number",
                f.next
            )));
        }
        let kind = f.text(&format!("type of lamps of set {k}"))?.to_string();
        let lumens = f.number(&format!("total flux of set {k}"))?;
        if k == 1 {
            first_flux_line = f.next;
        }
        let colour = f.text(&format!("colour of set {k}"))?.to_string();
        let colour_rendering = f.text(&format!("colour rendering of set {k}"))?.to_string();
        let watts = f.number(&format!("wattage of set {k}"))?;
        lamp_sets.push(LampSet {
            lamps: lamps as i64,
            kind,
            lumens,
            colour,
            colour_rendering,
            watts,
        });
    }
    if lamp_sets[0].lumens <= 0.0 {
        return Err(DecodeError::invalid(format!(
            "line {first_flux_line}: the total flux of lamp set 1 is {} lm; the intensities are \
             per 1000 of it, so it must be positive",
            lamp_sets[0].lumens
        )));
    }
    let mut direct_ratios = [0.0; 10];
    for (k, v) in direct_ratios.iter_mut().enumerate() {
        *v = f.number(&format!("direct ratio {}", k + 1))?;
    }

    let (stored_from, stored) = stored_planes(symmetry, c_planes)?;
    let n_values = stored
        .checked_mul(gamma_count)
        .filter(|&n| n <= limits.max_values)
        .ok_or_else(|| {
            DecodeError::Limits(format!(
                "{stored} stored planes of {gamma_count} intensities, over the limit of {} values",
                limits.max_values
            ))
        })?;
    let mut values = Values::new(&lines[f.next..], &[]);
    let needed = c_planes + gamma_count + n_values;
    if values.remaining() < needed {
        return Err(DecodeError::Limits(format!(
            "{c_planes} C angles, {gamma_count} gamma angles and {n_values} intensities need \
             {needed} values after line {}, and the file holds only {}",
            f.next,
            values.remaining()
        )));
    }
    let c_angles = values.angles("C", c_planes, 360.0, true)?;
    let gamma = values.angles("gamma", gamma_count, 180.0, true)?;
    let mut cd = Vec::with_capacity(n_values);
    for plane in 0..stored {
        for g in 0..gamma_count {
            let what = format!("intensity {} of stored plane {}", g + 1, plane + 1);
            let (v, line) = values.number(&what, true)?;
            if v < 0.0 {
                return Err(DecodeError::invalid(format!(
                    "line {line}: {what} is negative ({v})"
                )));
            }
            cd.push(v as f32);
        }
    }
    if let Some(extra) = values.rest().first() {
        return Err(DecodeError::invalid(format!(
            "line {}: {:?} follows the last intensity",
            extra.line, extra.text
        )));
    }
    let stored_angles = if symmetry == Symmetry::Axial {
        Vec::new()
    } else {
        c_angles[stored_from..stored_from + stored].to_vec()
    };
    check_stored_range(symmetry, &stored_angles)?;
    let scale = lamp_sets[0].lumens / 1000.0 * intensity_factor;
    let (h, cd) = symmetry::expand(symmetry, &stored_angles, &cd, gamma_count, scale);
    let v = gamma.iter().map(|&a| a as f32).collect();
    let table = CandelaTable::new(v, h, cd).map_err(|e| DecodeError::invalid(e.to_string()))?;
    Ok(LdtFile {
        identification,
        type_indicator,
        symmetry,
        c_planes,
        c_spacing_deg,
        gamma_count,
        gamma_spacing_deg,
        report_number,
        luminaire_name,
        luminaire_number,
        file_name,
        date_user,
        luminaire_mm,
        luminous_area_mm,
        luminous_heights_mm,
        downward_flux_fraction_percent,
        light_output_ratio_percent,
        intensity_factor,
        tilt_deg,
        lamp_sets,
        direct_ratios,
        table,
    })
}

/// The index of the first stored C plane and how many are stored, by `Isym` (module doc).
fn stored_planes(symmetry: Symmetry, nc: usize) -> Result<(usize, usize), DecodeError> {
    let needs = |divisor: usize, isym: u8| {
        if nc == 0 || !nc.is_multiple_of(divisor) {
            Err(DecodeError::invalid(format!(
                "line 4: Nc is {nc}, but Isym {isym} needs a positive multiple of {divisor}"
            )))
        } else {
            Ok(())
        }
    };
    match symmetry {
        Symmetry::Axial => Ok((0, 1)),
        Symmetry::None => needs(1, 0).map(|_| (0, nc)),
        Symmetry::PlaneC0C180 => needs(2, 2).map(|_| (0, nc / 2 + 1)),
        Symmetry::PlaneC90C270 => needs(4, 3).map(|_| (nc / 4, nc / 2 + 1)),
        Symmetry::Quadrant => needs(4, 4).map(|_| (0, nc / 4 + 1)),
    }
}

/// The stored planes must start and end where their symmetry's range does.
fn check_stored_range(symmetry: Symmetry, stored: &[f64]) -> Result<(), DecodeError> {
    let (isym, from, to) = match symmetry {
        Symmetry::Axial | Symmetry::None => return Ok(()),
        Symmetry::PlaneC0C180 => (2, 0.0, 180.0),
        Symmetry::PlaneC90C270 => (3, 90.0, 270.0),
        Symmetry::Quadrant => (4, 0.0, 90.0),
    };
    let (first, last) = (stored[0], stored[stored.len() - 1]);
    if near(first, from) && near(last, to) {
        Ok(())
    } else {
        Err(DecodeError::invalid(format!(
            "Isym {isym} stores the planes C{from} to C{to}, but the C angles there are {first} \
             and {last}"
        )))
    }
}
