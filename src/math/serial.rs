//! Serde forms of the vocabulary's nalgebra types, for the model's serialised description
//! ([`crate::model::fingerprint`]): a [`Vec3`] is the sequence of its three components, a [`Mat3`] the
//! sequence of its nine in column order (nalgebra's storage order), and options, lists and pairs of them are
//! serde's options, sequences and tuples. Fields use it as
//! `#[serde(serialize_with = "crate::math::serial::components")]`.
//!
//! nalgebra's own `serde-serialize` feature would serialise them too, but it also turns on `num-complex/serde`,
//! which rebuilds faer (minutes of a cold build) for nothing the crate uses. Nothing here reads or writes a
//! file: the description is hashed in memory.

use super::{Mat3, Vec3};
use serde::ser::{Serialize, SerializeTuple, Serializer};

/// A value made of vectors and matrices that serialises as their components ([module docs](self)).
pub(crate) trait Components {
    /// Serialises `self` into `serializer`.
    ///
    /// # Errors
    /// The serializer's.
    fn serialize_components<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error>;
}

/// Serialises `value` as its components: the `serialize_with` function of a field of a [`Components`] type.
///
/// # Errors
/// The serializer's.
pub(crate) fn components<T: Components, S: Serializer>(
    value: &T,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    value.serialize_components(serializer)
}

/// A borrowed [`Components`] value as a [`Serialize`] one (for the items of a list, option or pair).
struct AsComponents<'a, T>(&'a T);

impl<T: Components> Serialize for AsComponents<'_, T> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        self.0.serialize_components(serializer)
    }
}

impl Components for Vec3 {
    fn serialize_components<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

impl Components for Mat3 {
    fn serialize_components<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

impl<T: Components> Components for Option<T> {
    fn serialize_components<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            None => serializer.serialize_none(),
            Some(value) => serializer.serialize_some(&AsComponents(value)),
        }
    }
}

impl<T: Components> Components for Vec<T> {
    fn serialize_components<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter().map(AsComponents))
    }
}

impl<A: Components, B: Components> Components for (A, B) {
    fn serialize_components<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut pair = serializer.serialize_tuple(2)?;
        pair.serialize_element(&AsComponents(&self.0))?;
        pair.serialize_element(&AsComponents(&self.1))?;
        pair.end()
    }
}

#[cfg(test)]
mod tests {
    // Source: the module's contract — a vector is its components in order, a matrix its components in column
    // order (checked on a matrix whose entries name their row and column), as serde_json writes them.
    use super::*;

    #[derive(serde::Serialize)]
    struct Fields {
        #[serde(serialize_with = "components")]
        v: Vec3,
        #[serde(serialize_with = "components")]
        m: Mat3,
        #[serde(serialize_with = "components")]
        planes: Vec<(Vec3, Vec3)>,
        #[serde(serialize_with = "components")]
        hint: Option<Vec3>,
    }

    #[test]
    fn vectors_and_matrices_are_their_components_in_storage_order() {
        let fields = Fields {
            v: Vec3::new(1.0, -0.0, 2.5),
            // Entry (i, j) = 10 (i + 1) + (j + 1).
            m: Mat3::from_fn(|i, j| (10 * (i + 1) + j + 1) as f64),
            planes: vec![(Vec3::x(), Vec3::z())],
            hint: None,
        };
        let json = serde_json::to_string(&fields).expect("serialisable");
        assert_eq!(
            json,
            r#"{"v":[1.0,-0.0,2.5],"m":[11.0,21.0,31.0,12.0,22.0,32.0,13.0,23.0,33.0],"planes":[[[1.0,0.0,0.0],[0.0,0.0,1.0]]],"hint":null}"#
        );
    }
}
