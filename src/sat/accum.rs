//! The [`Accumulator`] trait: what a summed-area table stores per entry.
//!
//! Integer accumulators sum the stored integer codes (or, for straight
//! alpha, the products colour code × alpha code) and are exact as long as
//! the table's largest sum fits; [`super::required_bits`] decides that
//! before anything is allocated, so no table ever wraps around. Float
//! accumulators sum linear-light values and are approximate; they run the
//! build in f64 and round each entry once into the stored type, so the
//! error that remains is the storage precision of the entries (see the
//! module docs of [`crate::sat`] for the bounds).

use std::fmt;
use std::str::FromStr;

use crate::error::{Error, Result};

/// The accumulator kinds, as a value (for automatic choice, options and
/// reports).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AccumulatorKind {
    /// 32-bit unsigned integer: exact up to 2^32 − 1.
    U32,
    /// 64-bit unsigned integer: exact up to 2^64 − 1.
    U64,
    /// 128-bit unsigned integer: only needed above 2^48 texels of 16-bit
    /// data (or 2^32 texels of 16-bit straight-alpha data).
    U128,
    /// IEEE single float of the linear values.
    F32,
    /// IEEE single float of the linear values minus a per-channel offset
    /// (the channel mean), Hensley et al. 2005.
    OffsetF32,
    /// IEEE double float of the linear values.
    F64,
}

impl AccumulatorKind {
    /// All kinds, narrowest integer first, then the float kinds.
    pub const ALL: [AccumulatorKind; 6] = [
        AccumulatorKind::U32,
        AccumulatorKind::U64,
        AccumulatorKind::U128,
        AccumulatorKind::F32,
        AccumulatorKind::OffsetF32,
        AccumulatorKind::F64,
    ];

    /// Stable name: `u32`, `u64`, `u128`, `f32`, `offset-f32`, `f64`.
    pub fn name(self) -> &'static str {
        match self {
            AccumulatorKind::U32 => "u32",
            AccumulatorKind::U64 => "u64",
            AccumulatorKind::U128 => "u128",
            AccumulatorKind::F32 => "f32",
            AccumulatorKind::OffsetF32 => "offset-f32",
            AccumulatorKind::F64 => "f64",
        }
    }

    /// True for the exact integer kinds.
    pub fn is_integer(self) -> bool {
        matches!(
            self,
            AccumulatorKind::U32 | AccumulatorKind::U64 | AccumulatorKind::U128
        )
    }

    /// Bytes per table entry (one channel).
    pub fn bytes(self) -> usize {
        match self {
            AccumulatorKind::U32 | AccumulatorKind::F32 | AccumulatorKind::OffsetF32 => 4,
            AccumulatorKind::U64 | AccumulatorKind::F64 => 8,
            AccumulatorKind::U128 => 16,
        }
    }

    /// Integer kinds: the number of bits a sum may use. `None` for floats.
    pub fn integer_bits(self) -> Option<u32> {
        match self {
            AccumulatorKind::U32 => Some(32),
            AccumulatorKind::U64 => Some(64),
            AccumulatorKind::U128 => Some(128),
            _ => None,
        }
    }
}

impl fmt::Display for AccumulatorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for AccumulatorKind {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "u32" => AccumulatorKind::U32,
            "u64" => AccumulatorKind::U64,
            "u128" => AccumulatorKind::U128,
            "f32" => AccumulatorKind::F32,
            "offset-f32" | "offsetf32" => AccumulatorKind::OffsetF32,
            "f64" => AccumulatorKind::F64,
            _ => {
                return Err(Error::parse(
                    "accumulator",
                    s,
                    "expected u32, u64, u128, f32, offset-f32 or f64",
                ));
            }
        })
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for u32 {}
    impl Sealed for u64 {}
    impl Sealed for u128 {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
    impl Sealed for super::OffsetF32 {}
}

/// A table entry type. Sealed: the kinds are the ones in
/// [`AccumulatorKind`].
///
/// `Wide` is the type the build runs its sums in: the entry type itself
/// for integers (wrapping arithmetic, never reached because sizes are
/// checked first), f64 for the float kinds.
pub trait Accumulator:
    sealed::Sealed + Copy + Default + Send + Sync + fmt::Debug + 'static
{
    /// The kind, as a value.
    const KIND: AccumulatorKind;
    /// Type of running sums during the build.
    type Wide: Copy + Default + Send + Sync;
    /// An integer input value (a code, or a product of two codes).
    fn from_code(c: u32) -> Self::Wide;
    /// A linear-light input value (float kinds).
    fn from_linear(x: f64) -> Self::Wide;
    /// Running-sum addition.
    fn add(a: Self::Wide, b: Self::Wide) -> Self::Wide;
    /// Round (floats) or copy (integers) a running sum into an entry.
    fn store(w: Self::Wide) -> Self;
    /// The entry as f64 (exact for integers below 2^53).
    fn to_f64(self) -> f64;
    /// Entry difference; wrapping for integers (exact whenever the true
    /// difference fits, which the size check guarantees).
    fn sub(self, o: Self) -> Self;
    /// Entry sum; wrapping for integers.
    fn plus(self, o: Self) -> Self;
}

macro_rules! int_acc {
    ($t:ty, $kind:ident, $to_f64:expr) => {
        impl Accumulator for $t {
            const KIND: AccumulatorKind = AccumulatorKind::$kind;
            type Wide = $t;
            #[inline(always)]
            fn from_code(c: u32) -> $t {
                c as $t
            }
            #[inline(always)]
            fn from_linear(x: f64) -> $t {
                // Integer tables are only built from integer codes; this is
                // unreachable from the public API and saturates if called.
                x as $t
            }
            #[inline(always)]
            fn add(a: $t, b: $t) -> $t {
                a.wrapping_add(b)
            }
            #[inline(always)]
            fn store(w: $t) -> $t {
                w
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                $to_f64(self)
            }
            #[inline(always)]
            fn sub(self, o: $t) -> $t {
                self.wrapping_sub(o)
            }
            #[inline(always)]
            fn plus(self, o: $t) -> $t {
                self.wrapping_add(o)
            }
        }
    };
}

int_acc!(u32, U32, |v: u32| v as f64);
// Through i64 when the top bit is clear: a single instruction on x86-64,
// where the unsigned conversion takes a dozen.
int_acc!(u64, U64, |v: u64| if v >> 63 == 0 {
    v as i64 as f64
} else {
    v as f64
});
int_acc!(u128, U128, |v: u128| if v >> 63 == 0 {
    v as i64 as f64
} else {
    v as f64
});

macro_rules! float_acc {
    ($t:ty, $kind:ident, $store:expr, $get:expr) => {
        impl Accumulator for $t {
            const KIND: AccumulatorKind = AccumulatorKind::$kind;
            type Wide = f64;
            #[inline(always)]
            fn from_code(c: u32) -> f64 {
                c as f64
            }
            #[inline(always)]
            fn from_linear(x: f64) -> f64 {
                x
            }
            #[inline(always)]
            fn add(a: f64, b: f64) -> f64 {
                a + b
            }
            #[inline(always)]
            fn store(w: f64) -> $t {
                $store(w)
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                $get(self)
            }
            #[inline(always)]
            fn sub(self, o: $t) -> $t {
                $store($get(self) - $get(o))
            }
            #[inline(always)]
            fn plus(self, o: $t) -> $t {
                $store($get(self) + $get(o))
            }
        }
    };
}

/// An f32 entry of an offset table: the running sum of
/// `value − offset` (the table keeps the per-channel offsets and adds
/// `offset · area` back in every query).
#[derive(Clone, Copy, Debug, Default, PartialEq, PartialOrd)]
pub struct OffsetF32(pub f32);

float_acc!(f32, F32, |w: f64| w as f32, |s: f32| s as f64);
float_acc!(f64, F64, |w: f64| w, |s: f64| s);
float_acc!(
    OffsetF32,
    OffsetF32,
    |w: f64| OffsetF32(w as f32),
    |s: OffsetF32| s.0 as f64
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kind_names_round_trip() {
        for k in AccumulatorKind::ALL {
            assert_eq!(k.name().parse::<AccumulatorKind>().unwrap(), k);
        }
        assert!("u16".parse::<AccumulatorKind>().is_err());
    }
}
