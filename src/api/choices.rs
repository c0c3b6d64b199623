//! The choices of a request (lens model, calibration method), read by serde
//! from their names: an unknown name is an error naming the valid ones, at
//! parse time rather than deep in a solve. Re-exported by
//! [`super::camera`], whose requests (and stereo's and the rig's) hold them.

use super::camera::model_from_name;
use crate::calib::compare::Method;
use crate::camera::Distortion;
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// The lens model of a request: written as its name (`brown`, ...), read
/// from it by serde; an unknown name is an error naming the known ones.
/// Holds the model with the coefficients the solver starts from
/// ([`model_from_name`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LensModel(Distortion);

impl LensModel {
    /// The model of a name; unknown names are an error listing the known ones.
    pub fn from_name(name: &str) -> Result<LensModel> {
        model_from_name(name).map(LensModel)
    }

    /// The model's name.
    pub fn name(&self) -> &'static str {
        self.0.model_name()
    }

    /// The model with the coefficients the solver starts from.
    pub fn start(&self) -> &Distortion {
        &self.0
    }
}

impl Default for LensModel {
    /// `brown`.
    fn default() -> Self {
        LensModel(Distortion::Brown {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        })
    }
}

impl Serialize for LensModel {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for LensModel {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        LensModel::from_name(&name).map_err(serde::de::Error::custom)
    }
}

/// The method of a camera calibration request: one method, or `all`
/// (every method, compared). Written and read as its name; an unknown name
/// is an error naming the known ones.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodChoice {
    /// One method.
    One(Method),
    /// Every method, compared; the report is Zhang's (or better).
    All,
}

impl MethodChoice {
    /// The choice of a name (`zhang`, ..., `all`).
    pub fn from_name(name: &str) -> Result<MethodChoice> {
        match name {
            "all" => Ok(MethodChoice::All),
            _ => Method::from_name(name).map(MethodChoice::One),
        }
    }

    /// The choice's name.
    pub fn name(self) -> &'static str {
        match self {
            MethodChoice::One(m) => m.name(),
            MethodChoice::All => "all",
        }
    }
}

impl Default for MethodChoice {
    /// `zhang`.
    fn default() -> Self {
        MethodChoice::One(Method::Zhang)
    }
}

impl Serialize for MethodChoice {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for MethodChoice {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        MethodChoice::from_name(&name).map_err(serde::de::Error::custom)
    }
}
