//! The extraction methods by name (Madsen & Laursen 2006 section 3 compares them): what a scene
//! file's `[lighting] method`, a command line or a study asks for. Running them is `ibl-extract`'s
//! business; the record of a run, with its parameters, is [`crate::Extraction`].
//!
//! Median cut makes only powers of two (the paper's algorithm, at most
//! [`MAX_MEDIAN_CUT_SPLITS`] rounds); every other method takes any N >= 1; the dominant light
//! (`sun`) is exactly one light.

use std::fmt;
use std::str::FromStr;

/// Most rounds of median cut (2^16 lights).
pub const MAX_MEDIAN_CUT_SPLITS: u32 = 16;

/// A light-extraction method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Method {
    /// Median cut (Debevec 2005), 2^K lights.
    MedianCut,
    /// Median cut with any N.
    AdaptiveMedianCut,
    /// LightGen-style clustering (Cohen & Debevec 2001).
    LightGen,
    /// Variance minimisation (Viriyothai & Debevec 2009).
    VarianceMinimization,
    /// Irradiance optimisation (Madsen et al. 2003).
    IrradianceOptimization,
}

/// A name that is no method.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown method '{name}' (expected one of: {expected})")]
pub struct MethodError {
    /// The name given.
    pub name: String,
    /// The names accepted, comma-separated.
    pub expected: String,
}

impl MethodError {
    /// Always true: an unknown method name is the caller's input at fault.
    pub fn is_bad_input(&self) -> bool {
        true
    }
}

impl Method {
    /// Every method, in the order reports list them.
    pub const ALL: [Method; 5] = [
        Method::MedianCut,
        Method::AdaptiveMedianCut,
        Method::LightGen,
        Method::VarianceMinimization,
        Method::IrradianceOptimization,
    ];

    /// The method's name on the command line and in files (`median-cut`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Method::MedianCut => "median-cut",
            Method::AdaptiveMedianCut => "adaptive-median-cut",
            Method::LightGen => "lightgen",
            Method::VarianceMinimization => "variance-minimization",
            Method::IrradianceOptimization => "irradiance-optimization",
        }
    }

    /// True when the method can make exactly `n` lights (median cut: powers of two only).
    pub fn accepts(self, n: usize) -> bool {
        match self {
            Method::MedianCut => n.is_power_of_two() && n.trailing_zeros() <= MAX_MEDIAN_CUT_SPLITS,
            _ => n >= 1,
        }
    }

    /// True for methods whose lights stand for probe regions (their power sums to the probe's).
    pub fn is_region_based(self) -> bool {
        matches!(
            self,
            Method::MedianCut | Method::AdaptiveMedianCut | Method::VarianceMinimization
        )
    }

    /// The names of every method, comma-separated (for messages).
    pub fn names() -> String {
        Method::ALL.map(Method::name).join(", ")
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = MethodError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| MethodError {
                name: s.to_string(),
                expected: Method::names(),
            })
    }
}

/// Where directional lights come from: an extraction method (N lights) or the probe's dominant
/// compact light (`sun`, one light).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LightSource {
    /// An extraction method, N lights.
    Method(Method),
    /// The probe's dominant compact light, one light.
    Sun,
}

impl LightSource {
    /// The name on the command line and in scene files (`median-cut`, ..., `sun`).
    pub fn name(self) -> &'static str {
        match self {
            LightSource::Method(m) => m.name(),
            LightSource::Sun => "sun",
        }
    }

    /// True when the source can make exactly `n` lights (`sun`: only 1).
    pub fn accepts(self, n: usize) -> bool {
        match self {
            LightSource::Method(m) => m.accepts(n),
            LightSource::Sun => n == 1,
        }
    }
}

impl fmt::Display for LightSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for LightSource {
    type Err = MethodError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "sun" {
            return Ok(LightSource::Sun);
        }
        s.parse::<Method>()
            .map(LightSource::Method)
            .map_err(|e| MethodError {
                expected: format!("{}, sun", e.expected),
                ..e
            })
    }
}

impl From<Method> for LightSource {
    fn from(m: Method) -> Self {
        LightSource::Method(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>(), Ok(m));
            assert_eq!(m.name().parse::<LightSource>(), Ok(LightSource::Method(m)));
        }
        assert_eq!("sun".parse::<LightSource>(), Ok(LightSource::Sun));
        let e = "nope".parse::<LightSource>().unwrap_err();
        assert!(e.to_string().contains("median-cut") && e.to_string().ends_with("sun)"));
    }

    #[test]
    fn counts_each_method_accepts() {
        assert!(Method::MedianCut.accepts(16));
        assert!(!Method::MedianCut.accepts(12));
        assert!(!Method::MedianCut.accepts(1 << 17));
        assert!(Method::LightGen.accepts(12));
        assert!(!Method::LightGen.accepts(0));
        assert!(LightSource::Sun.accepts(1));
        assert!(!LightSource::Sun.accepts(2));
    }
}
