//! The drawing settings every renderer and every command names the same way. Each has
//! one spelling, its [`Display`](std::fmt::Display) form, which [`FromStr`] reads back:
//! the command line, the summaries, `--stats-json` and `tradeoff`'s table all use it.

use std::fmt;
use std::str::FromStr;

/// How intensities vary over a polygon.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Shading {
    /// One intensity per polygon (world scenes: lit once per face).
    Flat,
    /// Intensities interpolated along the edges and across each scanline (world scenes:
    /// lit at every vertex).
    #[default]
    Gouraud,
    /// World scenes: the normal and the point interpolated (perspective-correctly) over
    /// each triangle and lit at every pixel, sent through the span fitter.
    Phong,
    /// No shading at all (Woo & Chall's "hidden" mode, for timing visibility alone): a
    /// sample is 1 where the visible triangle changes from its left or upper neighbour
    /// (a visible edge), 0 elsewhere. Only renderers that resolve visibility per sample
    /// draw it.
    Hidden,
}

/// How a pixel's value is sampled from what covers it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Antialias {
    /// Point sampling at pixel centres.
    None,
    /// Box filter, exact: every pixel holds the integral of the intensity over the
    /// polygon's part of it (the covered area times the mean intensity there).
    #[default]
    Box,
    /// Box filter as van Rij's report computes it: the exact covered area times the
    /// intensity at the pixel centre (docs/ERRATA.md, D7). The same instructions as
    /// [`Antialias::Box`]; it differs only where the intensity varies (Gouraud).
    BoxCentre,
}

/// The names of a setting's values, in order, and the value of each.
trait Named: Sized + Copy + PartialEq + 'static {
    const WHAT: &'static str;
    const ALL: &'static [(Self, &'static str)];

    fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(v, _)| *v == self)
            .map(|(_, n)| *n)
            .expect("every value is named")
    }

    fn parse(s: &str) -> Result<Self, String> {
        Self::ALL
            .iter()
            .find(|(_, n)| n.eq_ignore_ascii_case(s))
            .map(|(v, _)| *v)
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|(_, n)| *n).collect();
                format!(
                    "unknown {} `{s}`; expected {}",
                    Self::WHAT,
                    names.join(" or ")
                )
            })
    }
}

impl Named for Shading {
    const WHAT: &'static str = "shading";
    const ALL: &'static [(Self, &'static str)] = &[
        (Shading::Flat, "flat"),
        (Shading::Gouraud, "gouraud"),
        (Shading::Phong, "phong"),
        (Shading::Hidden, "hidden"),
    ];
}

impl Named for Antialias {
    const WHAT: &'static str = "anti-aliasing";
    const ALL: &'static [(Self, &'static str)] = &[
        (Antialias::None, "none"),
        (Antialias::Box, "box"),
        (Antialias::BoxCentre, "box-centre"),
    ];
}

impl Shading {
    /// Every value, in order.
    pub const ALL: [Shading; 4] = [
        Shading::Flat,
        Shading::Gouraud,
        Shading::Phong,
        Shading::Hidden,
    ];

    /// Its one spelling: "flat", "gouraud" (the [`Display`](fmt::Display) form).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// How a summary says it: "flat" or "Gouraud".
    pub fn title(self) -> &'static str {
        match self {
            Shading::Flat => "flat",
            Shading::Gouraud => "Gouraud",
            Shading::Phong => "Phong",
            Shading::Hidden => "no (hidden-line)",
        }
    }
}

impl Antialias {
    /// Every value, in order.
    pub const ALL: [Antialias; 3] = [Antialias::None, Antialias::Box, Antialias::BoxCentre];

    /// Its one spelling: "none", "box", "box-centre" (the [`Display`](fmt::Display)
    /// form).
    pub fn name(self) -> &'static str {
        Named::name(self)
    }

    /// How a summary says it: "point sampling", "box filter (exact)" or "box filter
    /// (coverage × centre value)".
    pub fn title(self) -> &'static str {
        match self {
            Antialias::None => "point sampling",
            Antialias::Box => "box filter (exact)",
            Antialias::BoxCentre => "box filter (coverage × centre value)",
        }
    }

    /// A box filter, exact or the report's: the pixels' covered area counts.
    pub fn is_box(self) -> bool {
        matches!(self, Antialias::Box | Antialias::BoxCentre)
    }
}

macro_rules! display_and_parse {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(Named::name(*self))
            }
        }

        impl FromStr for $t {
            type Err = String;

            fn from_str(s: &str) -> Result<Self, String> {
                <$t as Named>::parse(s)
            }
        }
    )*};
}

display_and_parse!(Shading, Antialias);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_back() {
        for s in Shading::ALL {
            assert_eq!(s.to_string().parse::<Shading>(), Ok(s));
        }
        for a in Antialias::ALL {
            assert_eq!(a.to_string().parse::<Antialias>(), Ok(a));
        }
        assert_eq!("GOURAUD".parse::<Shading>(), Ok(Shading::Gouraud));
        assert_eq!(
            "metal".parse::<Shading>().unwrap_err(),
            "unknown shading `metal`; expected flat or gouraud or phong or hidden"
        );
        assert_eq!(Antialias::Box.to_string(), "box");
        assert_eq!(Antialias::BoxCentre.to_string(), "box-centre");
        assert_eq!("Box-Centre".parse::<Antialias>(), Ok(Antialias::BoxCentre));
        assert_eq!(
            "centre".parse::<Antialias>().unwrap_err(),
            "unknown anti-aliasing `centre`; expected none or box or box-centre"
        );
    }
}
