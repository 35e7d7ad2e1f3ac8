//! Two- and three-component vectors of `f64` for positions, velocities and offsets.
//!
//! Each operation is the plain expression on its components (`x * x + y * y` for the squared
//! norm, a component divided by the norm for the unit vector), so results are the same to the bit
//! on every machine and do not depend on a linear-algebra library's choice of evaluation order.
//! They serialize as arrays (`[x, y]`, `[x, y, z]`).

use std::fmt;
use std::ops::{
    Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign,
};

/// `a OP b` for every mix of values and references, as the values' operation.
macro_rules! forward_refs {
    ($name:ident, $op:ident, $f:ident) => {
        impl $op<&$name> for $name {
            type Output = $name;
            #[inline]
            fn $f(self, o: &$name) -> $name {
                $op::$f(self, *o)
            }
        }

        impl $op<$name> for &$name {
            type Output = $name;
            #[inline]
            fn $f(self, o: $name) -> $name {
                $op::$f(*self, o)
            }
        }

        impl $op<&$name> for &$name {
            type Output = $name;
            #[inline]
            fn $f(self, o: &$name) -> $name {
                $op::$f(*self, *o)
            }
        }
    };
}

macro_rules! vector {
    ($name:ident, $n:literal, $what:literal, [$($f:ident = $i:literal),+]) => {
        #[doc = $what]
        #[derive(Clone, Copy, PartialEq, Default)]
        pub struct $name {
            $(
                #[doc = concat!("Component ", stringify!($i), ".")]
                pub $f: f64,
            )+
        }

        impl $name {
            /// The vector of these components.
            #[inline]
            pub const fn new($($f: f64),+) -> Self {
                Self { $($f),+ }
            }

            /// The zero vector.
            #[inline]
            pub const fn zeros() -> Self {
                Self { $($f: 0.0),+ }
            }

            /// Every component `v`.
            #[inline]
            pub const fn repeat(v: f64) -> Self {
                Self { $($f: v),+ }
            }

            /// The dot product: the component products summed in order, from the first.
            #[inline]
            pub fn dot(&self, o: &Self) -> f64 {
                let p = [$(self.$f * o.$f),+];
                p[1..].iter().fold(p[0], |a, b| a + b)
            }

            /// The squared Euclidean length.
            #[inline]
            pub fn norm_squared(&self) -> f64 {
                self.dot(self)
            }

            /// The Euclidean length.
            #[inline]
            pub fn norm(&self) -> f64 {
                self.norm_squared().sqrt()
            }

            /// The vector divided by its length (not finite for the zero vector).
            #[inline]
            pub fn normalize(&self) -> Self {
                *self / self.norm()
            }

            /// Every component times `s`.
            #[inline]
            pub fn scale(&self, s: f64) -> Self {
                *self * s
            }

            /// Each component through `f`.
            #[inline]
            pub fn map(&self, f: impl Fn(f64) -> f64) -> Self {
                Self { $($f: f(self.$f)),+ }
            }

            /// The components in order.
            #[inline]
            pub fn iter(&self) -> impl Iterator<Item = f64> {
                [$(self.$f),+].into_iter()
            }

            /// Whether every component is finite.
            #[inline]
            pub fn is_finite(&self) -> bool {
                true $(&& self.$f.is_finite())+
            }

            /// The components as an array.
            #[inline]
            pub const fn to_array(&self) -> [f64; $n] {
                [$(self.$f),+]
            }
        }

        impl From<[f64; $n]> for $name {
            #[inline]
            fn from(a: [f64; $n]) -> Self {
                Self { $($f: a[$i]),+ }
            }
        }

        impl From<$name> for [f64; $n] {
            #[inline]
            fn from(v: $name) -> Self {
                v.to_array()
            }
        }

        impl fmt::Debug for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.debug_list().entries([$(self.$f),+]).finish()
            }
        }

        impl Index<usize> for $name {
            type Output = f64;
            #[inline]
            fn index(&self, i: usize) -> &f64 {
                match i {
                    $($i => &self.$f,)+
                    _ => panic!("index {i} out of range for a vector of {} components", $n),
                }
            }
        }

        impl IndexMut<usize> for $name {
            #[inline]
            fn index_mut(&mut self, i: usize) -> &mut f64 {
                match i {
                    $($i => &mut self.$f,)+
                    _ => panic!("index {i} out of range for a vector of {} components", $n),
                }
            }
        }

        impl Add for $name {
            type Output = Self;
            #[inline]
            fn add(self, o: Self) -> Self {
                Self { $($f: self.$f + o.$f),+ }
            }
        }

        impl Sub for $name {
            type Output = Self;
            #[inline]
            fn sub(self, o: Self) -> Self {
                Self { $($f: self.$f - o.$f),+ }
            }
        }

        impl Neg for $name {
            type Output = Self;
            #[inline]
            fn neg(self) -> Self {
                Self { $($f: -self.$f),+ }
            }
        }

        impl Mul<f64> for $name {
            type Output = Self;
            #[inline]
            fn mul(self, s: f64) -> Self {
                Self { $($f: self.$f * s),+ }
            }
        }

        impl Mul<$name> for f64 {
            type Output = $name;
            #[inline]
            fn mul(self, v: $name) -> $name {
                v * self
            }
        }

        impl Div<f64> for $name {
            type Output = Self;
            #[inline]
            fn div(self, s: f64) -> Self {
                Self { $($f: self.$f / s),+ }
            }
        }

        forward_refs!($name, Add, add);
        forward_refs!($name, Sub, sub);

        impl Neg for &$name {
            type Output = $name;
            #[inline]
            fn neg(self) -> $name {
                -*self
            }
        }

        impl Mul<f64> for &$name {
            type Output = $name;
            #[inline]
            fn mul(self, s: f64) -> $name {
                *self * s
            }
        }

        impl Mul<&$name> for f64 {
            type Output = $name;
            #[inline]
            fn mul(self, v: &$name) -> $name {
                *v * self
            }
        }

        impl Div<f64> for &$name {
            type Output = $name;
            #[inline]
            fn div(self, s: f64) -> $name {
                *self / s
            }
        }

        impl AddAssign<&$name> for $name {
            #[inline]
            fn add_assign(&mut self, o: &$name) {
                *self = *self + *o;
            }
        }

        impl SubAssign<&$name> for $name {
            #[inline]
            fn sub_assign(&mut self, o: &$name) {
                *self = *self - *o;
            }
        }

        impl AddAssign for $name {
            #[inline]
            fn add_assign(&mut self, o: Self) {
                *self = *self + o;
            }
        }

        impl SubAssign for $name {
            #[inline]
            fn sub_assign(&mut self, o: Self) {
                *self = *self - o;
            }
        }

        impl MulAssign<f64> for $name {
            #[inline]
            fn mul_assign(&mut self, s: f64) {
                *self = *self * s;
            }
        }

        impl DivAssign<f64> for $name {
            #[inline]
            fn div_assign(&mut self, s: f64) {
                *self = *self / s;
            }
        }

        impl std::iter::Sum for $name {
            fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
                iter.fold(Self::zeros(), |a, b| a + b)
            }
        }

        impl<'a> std::iter::Sum<&'a $name> for $name {
            fn sum<I: Iterator<Item = &'a Self>>(iter: I) -> Self {
                iter.fold(Self::zeros(), |a, b| a + *b)
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                use serde::ser::SerializeTuple;
                let mut t = s.serialize_tuple($n)?;
                $(t.serialize_element(&self.$f)?;)+
                t.end()
            }
        }

        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                struct Seq;
                impl<'de> serde::de::Visitor<'de> for Seq {
                    type Value = $name;
                    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                        write!(f, "an array of {} numbers", $n)
                    }
                    fn visit_seq<A: serde::de::SeqAccess<'de>>(
                        self,
                        mut seq: A,
                    ) -> Result<$name, A::Error> {
                        let mut out = [0.0; $n];
                        let mut count = 0;
                        while let Some(v) = seq.next_element::<f64>()? {
                            if count == $n {
                                return Err(serde::de::Error::invalid_length(count + 1, &self));
                            }
                            out[count] = v;
                            count += 1;
                        }
                        if count < $n {
                            return Err(serde::de::Error::invalid_length(count, &self));
                        }
                        Ok($name::from(out))
                    }
                }
                d.deserialize_tuple($n, Seq)
            }
        }
    };
}

vector!(
    Vec2,
    2,
    "A horizontal vector or position `(east, north)` in metres (or m/s for velocities).",
    [x = 0, y = 1]
);
vector!(
    Vec3,
    3,
    "A 3-D vector or position `(east, north, up)`; for positions `z` is the height above the \
     seabed.",
    [x = 0, y = 1, z = 2]
);

impl Vec3 {
    /// The horizontal part `(x, y)`.
    #[inline]
    pub fn xy(&self) -> Vec2 {
        Vec2::new(self.x, self.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operations_are_the_plain_expressions_on_components() {
        let a = Vec2::new(3.0, -4.0);
        let b = Vec2::new(0.1, 0.7);
        assert_eq!(a.norm(), 5.0);
        assert_eq!(a.dot(&b).to_bits(), (3.0f64 * 0.1 + -4.0 * 0.7).to_bits());
        assert_eq!(a.normalize(), Vec2::new(3.0 / 5.0, -4.0 / 5.0));
        assert_eq!(2.0 * a, a * 2.0);
        assert_eq!(a / 2.0, Vec2::new(1.5, -2.0));
        assert_eq!(-a + a, Vec2::zeros());
        assert_eq!([a, b].iter().sum::<Vec2>(), a + b);
        let c = Vec3::new(1.0, 2.0, 2.0);
        assert_eq!(c.norm(), 3.0);
        assert_eq!(c.xy(), Vec2::new(1.0, 2.0));
        assert_eq!(c[2], 2.0);
        assert_eq!(format!("{a:?}"), "[3.0, -4.0]");
    }

    #[test]
    fn vectors_read_and_write_as_arrays() {
        #[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
        struct P {
            p: Vec2,
        }
        let text = toml::to_string(&P {
            p: Vec2::new(1.5, -2.0),
        })
        .unwrap();
        assert_eq!(text.trim(), "p = [1.5, -2.0]");
        assert_eq!(toml::from_str::<P>(&text).unwrap().p, Vec2::new(1.5, -2.0));
        for bad in ["p = [1.0]", "p = [1.0, 2.0, 3.0]", "p = 1.0"] {
            let e = toml::from_str::<P>(bad).unwrap_err().to_string();
            assert!(e.contains("an array of 2 numbers"), "{bad}: {e}");
        }
    }
}
