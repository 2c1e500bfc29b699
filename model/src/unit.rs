//! The interface every streaming unit stands behind, model and RTL alike, so one test drives
//! either and a scoreboard compares them in order.

use std::fmt::{Debug, Display};
use std::ops::RangeInclusive;

/// A streaming unit: items in, items out, one output per input, in order.
///
/// The golden model implements it directly; the test bench wraps a Verilator model in it. Timing
/// (latency, stalls) is not part of this view: only the sequence of values is.
pub trait StreamUnit {
    type In: Clone + Debug;
    type Out: Clone + Debug + PartialEq;

    /// Processes `inputs` in order and returns one output per input.
    fn run(&mut self, inputs: &[Self::In]) -> Vec<Self::Out>;

    /// Returns the unit to its state after reset (a no-op for stateless units).
    fn reset(&mut self) {}
}

/// How a unit's items become the flat bit vectors on the RTL ports (`docs/numerics.md`).
pub trait StreamCodec {
    type In;
    type Out;

    fn in_width(&self) -> u32;
    fn out_width(&self) -> u32;
    fn pack_in(&self, item: &Self::In) -> Vec<u32>;
    fn unpack_out(&self, words: &[u32]) -> Self::Out;
}

/// A unit's configuration as the parameters of its RTL top: the model is built from the same
/// `Param = value` pairs as the RTL (the variant table in `tb-rs` hands them over), and gives back
/// every parameter so a test can hold it to what the RTL elaborates.
pub trait UnitConfig: Sized {
    /// The RTL top this configuration parameterises.
    const TOP: &'static str;

    /// The configuration for `params`; a parameter not given keeps the RTL's default (which the
    /// model's default equals: `tb-rs/tests/variant_table.rs` checks it). An unknown parameter or
    /// an invalid combination is an error.
    fn from_params(params: &[(&str, i64)]) -> crate::Result<Self>;

    /// Every top-level parameter of the RTL with its value under this configuration.
    fn to_params(&self) -> Vec<(&'static str, i64)>;
}

/// Sets `fields` (RTL parameter name, model field) from `params`; `top` names the unit in errors.
pub fn set_params(
    top: &str,
    params: &[(&str, i64)],
    fields: &mut [(&'static str, &mut u32)],
) -> crate::Result<()> {
    for &(name, value) in params {
        let Some((_, field)) = fields.iter_mut().find(|(n, _)| *n == name) else {
            let known: Vec<&str> = fields.iter().map(|(n, _)| *n).collect();
            return Err(crate::ModelError::Config(format!(
                "{top}: unknown parameter {name} (known: {})",
                known.join(", ")
            )));
        };
        **field = u32::try_from(value).map_err(|_| {
            crate::ModelError::Config(format!("{top}: {name} = {value} is out of range"))
        })?;
    }
    Ok(())
}

/// Implements [`StreamUnit`] for a unit whose output for an item depends on that item alone (reset
/// a no-op): `item_by_item!(Trilin, TrilinIn => u32, |unit, item| unit.sample(item))`.
#[macro_export]
macro_rules! item_by_item {
    ($ty:ty, $in:ty => $out:ty, |$unit:ident, $item:ident| $body:expr) => {
        impl $crate::unit::StreamUnit for $ty {
            type In = $in;
            type Out = $out;

            fn run(&mut self, inputs: &[$in]) -> Vec<$out> {
                let $unit = &*self;
                inputs.iter().map(|$item| $body).collect()
            }
        }
    };
}

/// Implements [`UnitConfig`] for a configuration whose fields are its RTL parameters one to one:
/// `unit_config!(TrilinConfig, "cube5_trilin", DEFAULT, { "VoxelW" => voxel_w, ... })`.
/// `DEFAULT` equals the RTL's defaults; `validate()` checks the result.
#[macro_export]
macro_rules! unit_config {
    ($ty:ty, $top:literal, $default:ident, { $($name:literal => $field:ident),+ $(,)? }) => {
        impl $crate::unit::UnitConfig for $ty {
            const TOP: &'static str = $top;

            fn from_params(params: &[(&str, i64)]) -> $crate::Result<Self> {
                let mut c = <$ty>::$default;
                $crate::unit::set_params($top, params, &mut [$(($name, &mut c.$field)),+])?;
                c.validate()?;
                Ok(c)
            }

            fn to_params(&self) -> Vec<(&'static str, i64)> {
                vec![$(($name, i64::from(self.$field))),+]
            }
        }
    };
    // A top that wraps another unit's top: its own parameters as fields, and the listed parameters
    // of the unit inside passed through to its configuration in field `$inner` (which keeps its
    // own names, defaults and checks): `unit_config!(RingRtlConfig, "gicube_ring", DEFAULT,
    // { "ProcLog2" => proc_log2 }, proc: ["BlockLog2", "VolBlocks", ...])`.
    ($ty:ty, $top:literal, $default:ident, { $($name:literal => $field:ident),* $(,)? },
     $inner:ident: [$($fwd:literal),+ $(,)?]) => {
        impl $crate::unit::UnitConfig for $ty {
            const TOP: &'static str = $top;

            fn from_params(params: &[(&str, i64)]) -> $crate::Result<Self> {
                let mut c = <$ty>::$default;
                let own = $crate::unit::forward_params(
                    $top,
                    params,
                    &[$($name),*],
                    (&mut c.$inner, &[$($fwd),+]),
                )?;
                $crate::unit::set_params($top, &own, &mut [$(($name, &mut c.$field)),*])?;
                c.validate()?;
                Ok(c)
            }

            fn to_params(&self) -> Vec<(&'static str, i64)> {
                let mut p = vec![$(($name, i64::from(self.$field))),*];
                let fwd = [$($fwd),+];
                p.extend(
                    $crate::unit::UnitConfig::to_params(&self.$inner)
                        .into_iter()
                        .filter(|(n, _)| fwd.contains(n)),
                );
                p
            }
        }
    };
}

/// For a top that wraps another unit's ([`unit_config!`]'s second form): sets the parameters of
/// `params` named in `forwarded` on `inner` (through its own `from_params`, the others at their
/// values in `inner`) and returns the rest, which must be among `own`.
pub fn forward_params<'a, C: UnitConfig>(
    top: &str,
    params: &[(&'a str, i64)],
    own: &[&str],
    (inner, forwarded): (&mut C, &[&str]),
) -> crate::Result<Vec<(&'a str, i64)>> {
    let mut merged = inner.to_params();
    let mut rest = Vec::new();
    for &(name, value) in params {
        if let Some(slot) = merged
            .iter_mut()
            .find(|(n, _)| *n == name && forwarded.contains(n))
        {
            slot.1 = value;
        } else if own.contains(&name) {
            rest.push((name, value));
        } else {
            return Err(crate::ModelError::Config(format!(
                "{top}: unknown parameter {name} (known: {})",
                [own, forwarded].concat().join(", ")
            )));
        }
    }
    // An error names the unit inside (its parameters keep their names).
    *inner = C::from_params(&merged)?;
    Ok(rest)
}

/// A unit parameter's range check, as every unit's `validate` words it: `Err("{name} {v} outside
/// {lo}..={hi}")` (for the unit's own `bad`, which names the unit) unless `v` lies in `range`.
pub fn param_in<T: PartialOrd + Display>(
    name: &str,
    v: T,
    range: RangeInclusive<T>,
) -> std::result::Result<(), String> {
    if range.contains(&v) {
        Ok(())
    } else {
        Err(format!(
            "{name} {v} outside {}..={}",
            range.start(),
            range.end()
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::UnitConfig;

    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Inner {
        a: u32,
        b: u32,
    }

    impl Inner {
        const DEFAULT: Self = Self { a: 1, b: 2 };

        fn validate(&self) -> crate::Result<()> {
            super::param_in("A", self.a, 1..=9).map_err(crate::ModelError::Config)
        }
    }

    crate::unit_config!(Inner, "inner", DEFAULT, { "A" => a, "B" => b });

    /// A top wrapping `Inner` with `B = 3` and only `A` passed through.
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Outer {
        k: u32,
        inner: Inner,
    }

    impl Outer {
        const DEFAULT: Self = Self {
            k: 4,
            inner: Inner { a: 1, b: 3 },
        };

        fn validate(&self) -> crate::Result<()> {
            self.inner.validate()
        }
    }

    crate::unit_config!(Outer, "outer", DEFAULT, { "K" => k }, inner: ["A"]);

    #[test]
    fn a_wrapping_top_passes_the_listed_parameters_through() {
        let c = Outer::from_params(&[("A", 7), ("K", 5)]).unwrap();
        assert_eq!(
            c,
            Outer {
                k: 5,
                inner: Inner { a: 7, b: 3 }
            }
        );
        assert_eq!(c.to_params(), vec![("K", 5), ("A", 7)]);
        assert_eq!(Outer::from_params(&[]).unwrap(), Outer::DEFAULT);
        // A parameter of the unit inside that the top does not pass through is unknown.
        let e = Outer::from_params(&[("B", 1)]).unwrap_err().to_string();
        assert!(
            e.contains("outer: unknown parameter B (known: K, A)"),
            "{e}"
        );
        // The unit inside checks its own.
        let e = Outer::from_params(&[("A", 10)]).unwrap_err().to_string();
        assert!(e.contains("A 10 outside 1..=9"), "{e}");
    }
}
