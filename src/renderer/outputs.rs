//! Which of a view's images a frame reads back ([`Output`], [`Outputs`]),
//! and how each is laid out in the readback memory ([`Element`]).

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};

/// One image of a rendered view that can be read back to the host.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Output {
    /// Tone-mapped sRGB, 4 × u8 per pixel.
    Rgba8,
    /// Linear HDR radiance, 4 × f32 per pixel (alpha 1).
    Hdr,
    /// View-space depth along the camera's forward axis, metres (f32; +inf for sky).
    Depth,
    /// Euclidean distance from the eye along the pixel's ray, metres (f32; +inf for sky).
    Distance,
    /// World-space shading normal (stored as 4 × f16, read as 3 × f32; 0 for sky).
    Normal,
    /// Semantic class per pixel (u32; stored interleaved with the instance id).
    Class,
    /// Point instance id per pixel (u32, 1-based; 0 for terrain and sky).
    Instance,
    /// Motion from the previous frame in pixels, 2 × f32 (+x right, +y down).
    Motion,
    /// Sun and sky visibility, 2 × f32 (1 = lit, open sky).
    Visibility,
    /// Accumulated EWA splat weight (f32); only in scenes with point objects.
    Weight,
}

impl Output {
    /// Every output, in declaration order.
    pub const ALL: [Output; 10] = [
        Output::Rgba8,
        Output::Hdr,
        Output::Depth,
        Output::Distance,
        Output::Normal,
        Output::Class,
        Output::Instance,
        Output::Motion,
        Output::Visibility,
        Output::Weight,
    ];

    /// The output's name: `rgba8`, `hdr`, `depth`, `distance`, `normal`,
    /// `class`, `instance`, `motion`, `visibility` or `weight`.
    pub fn name(self) -> &'static str {
        match self {
            Output::Rgba8 => "rgba8",
            Output::Hdr => "hdr",
            Output::Depth => "depth",
            Output::Distance => "distance",
            Output::Normal => "normal",
            Output::Class => "class",
            Output::Instance => "instance",
            Output::Motion => "motion",
            Output::Visibility => "visibility",
            Output::Weight => "weight",
        }
    }

    /// The element type of the output as handed to the caller by the
    /// `copy_into` helpers ([`super::Plane::copy_into`]).
    pub fn element(self) -> Element {
        match self {
            Output::Rgba8 => Element::U8,
            Output::Class | Output::Instance => Element::U32,
            _ => Element::F32,
        }
    }

    /// Channels per pixel as handed to the caller (rgba8 and hdr 4, normal
    /// 3, motion and visibility 2, the others 1).
    pub fn channels(self) -> usize {
        match self {
            Output::Rgba8 | Output::Hdr => 4,
            Output::Normal => 3,
            Output::Motion | Output::Visibility => 2,
            _ => 1,
        }
    }

    /// Bytes per pixel as handed to the caller (`channels × element size`).
    pub fn bytes_per_pixel(self) -> usize {
        self.channels() * self.element().size()
    }

    fn bit(self) -> u16 {
        1 << (self as u16)
    }
}

impl fmt::Display for Output {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Output {
    type Err = Error;

    /// An output by its [`Output::name`].
    fn from_str(s: &str) -> Result<Output> {
        Output::ALL.into_iter().find(|o| o.name() == s).ok_or_else(|| {
            let names: Vec<&str> = Output::ALL.iter().map(|o| o.name()).collect();
            Error::invalid("output", format!("'{s}' is not one of {}", names.join(", ")))
        })
    }
}

/// A set of [`Output`]s: which images every frame copies to the host
/// (copies of the others are skipped). Default: all of them.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Outputs(u16);

impl Outputs {
    /// Every output.
    pub const ALL: Outputs = Outputs((1 << Output::ALL.len()) - 1);
    /// No output (nothing is read back).
    pub const NONE: Outputs = Outputs(0);

    /// The set of `outputs`.
    pub fn of(outputs: &[Output]) -> Outputs {
        Outputs(outputs.iter().fold(0, |bits, o| bits | o.bit()))
    }

    /// Whether `output` is in the set.
    pub fn contains(self, output: Output) -> bool {
        self.0 & output.bit() != 0
    }

    /// The set with `output` added.
    pub fn with(self, output: Output) -> Outputs {
        Outputs(self.0 | output.bit())
    }

    /// The set with `output` removed.
    pub fn without(self, output: Output) -> Outputs {
        Outputs(self.0 & !output.bit())
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The outputs in the set, in [`Output::ALL`] order.
    pub fn iter(self) -> impl Iterator<Item = Output> {
        Output::ALL.into_iter().filter(move |o| self.contains(*o))
    }
}

impl Default for Outputs {
    fn default() -> Outputs {
        Outputs::ALL
    }
}

impl fmt::Debug for Outputs {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_set().entries(self.iter()).finish()
    }
}

impl FromIterator<Output> for Outputs {
    fn from_iter<I: IntoIterator<Item = Output>>(iter: I) -> Outputs {
        iter.into_iter().fold(Outputs::NONE, Outputs::with)
    }
}

/// The element type of a plane's samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Element {
    U8,
    /// IEEE 754 binary16.
    F16,
    F32,
    U32,
}

impl Element {
    /// Bytes per sample.
    pub fn size(self) -> usize {
        match self {
            Element::U8 => 1,
            Element::F16 => 2,
            Element::F32 | Element::U32 => 4,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_and_names() {
        let set = Outputs::of(&[Output::Rgba8, Output::Class]);
        assert!(set.contains(Output::Rgba8) && set.contains(Output::Class));
        assert!(!set.contains(Output::Instance));
        assert_eq!(set.iter().collect::<Vec<_>>(), [Output::Rgba8, Output::Class]);
        assert_eq!(Outputs::ALL.iter().count(), 10);
        assert!(Outputs::NONE.is_empty());
        assert_eq!(
            set.without(Output::Class).with(Output::Hdr),
            Outputs::of(&[Output::Rgba8, Output::Hdr])
        );
        for o in Output::ALL {
            assert_eq!(o.name().parse::<Output>().expect("name"), o);
        }
        let e = "rgb".parse::<Output>().expect_err("unknown");
        assert!(e.to_string().contains("'rgb'"), "{e}");
        assert_eq!(Output::Normal.bytes_per_pixel(), 12);
    }
}
