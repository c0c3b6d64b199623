//! The lens-model table: every model the solvers fit, once, with what each
//! host says about it. The CLI's `--model` help and errors, the JSON
//! errors, the model advice, the page's lens list and the npm package
//! (`lens_models()` in wasm) are made from [`LENS_MODELS`]; adding a model
//! is a [`Distortion`] variant (the compiler leads through its match arms)
//! plus one row here (the tests below check the row against the variant,
//! `io`'s tests check the export formats against the writers).

use super::{splined, Distortion, Spline};

/// One lens model: its name in JSON and on the command line, what people
/// call it, its coefficients and where the solvers start them, and the
/// camera export formats that can hold it.
#[derive(Clone, Debug, PartialEq)]
pub struct LensModel {
    /// The `model` of the JSON and `--model` (also [`Distortion::model_name`]).
    pub name: &'static str,
    /// Other names accepted for the model, each with what it means
    /// (`brown5`: OpenCV's five coefficients).
    pub aliases: &'static [(&'static str, &'static str)],
    /// The short name the model advice writes ("the Brown-Conrady model").
    pub label: &'static str,
    /// The longer text of the page's lens list: the label with the
    /// coefficients and the tools that know the model.
    pub description: &'static str,
    /// Coefficient names, in the order of [`Distortion::coefficients`].
    pub coefficients: &'static [&'static str],
    /// The model with the coefficients the solvers start from (0, except
    /// EUCM's alpha 0.5 and beta 1: at alpha = 0 beta has no effect).
    pub start: Distortion,
    /// The camera formats of `robocal export` that hold the model (`text`,
    /// which holds no lens model, left out); a condition in parentheses says
    /// what the coefficients must be, e.g. `kalibr (with k3 held at 0)`.
    pub export_formats: &'static [&'static str],
    /// A model for lenses past 90 degrees (the model advice always compares
    /// these for a wide-angle lens).
    pub wide_angle: bool,
}

/// Every camera format but `text`: what a pinhole camera exports to.
const ALL_CAMERA_FORMATS: &[&str] = &[
    "json",
    "opencv-yaml",
    "opencv-xml",
    "ros-yaml",
    "kalibr",
    "mrcal",
    "halcon",
    "matlab",
];

/// How many lens models the table holds.
const N_MODELS: usize = 9;

/// The lens models, in the order of the menus (the default, `brown`, first).
/// A static (not a const): the splined model's start owns a (empty) vector.
pub static LENS_MODELS: [LensModel; N_MODELS] = [
    LensModel {
        name: "brown",
        aliases: &[("brown5", "OpenCV's 5 coefficients")],
        label: "Brown-Conrady",
        description: "Brown-Conrady (radial k1 k2 k3, tangential p1 p2: OpenCV, MATLAB, Bouguet, Kalibr radtan)",
        coefficients: &["k1", "k2", "p1", "p2", "k3"],
        start: Distortion::Brown {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            p1: 0.0,
            p2: 0.0,
        },
        export_formats: &[
            "json",
            "opencv-yaml",
            "opencv-xml",
            "ros-yaml",
            "kalibr (with k3 held at 0)",
            "mrcal",
            "halcon",
            "matlab",
        ],
        wide_angle: false,
    },
    LensModel {
        name: "radial_k1_k2_k5",
        aliases: &[],
        label: "radial k1 k2 k5",
        description: "Brown-Conrady radial only, Bouguet numbering (k1 k2 k5)",
        coefficients: &["k1", "k2", "k5"],
        start: Distortion::RadialK1K2K5 {
            k1: 0.0,
            k2: 0.0,
            k5: 0.0,
        },
        export_formats: &[
            "json",
            "opencv-yaml",
            "opencv-xml",
            "ros-yaml",
            "kalibr (with k5 held at 0)",
            "mrcal",
            "halcon",
            "matlab",
        ],
        wide_angle: false,
    },
    LensModel {
        name: "rational",
        aliases: &[],
        label: "rational",
        description: "OpenCV rational (k1..k6, p1 p2, thin prism s1..s4)",
        coefficients: &[
            "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4",
        ],
        start: Distortion::Rational {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            k4: 0.0,
            k5: 0.0,
            k6: 0.0,
            p1: 0.0,
            p2: 0.0,
            s1: 0.0,
            s2: 0.0,
            s3: 0.0,
            s4: 0.0,
        },
        export_formats: &["json", "opencv-yaml", "opencv-xml", "ros-yaml", "mrcal"],
        wide_angle: false,
    },
    LensModel {
        name: "division",
        aliases: &[],
        label: "division",
        description: "Division (Fitzgibbon, Halcon)",
        coefficients: &["kappa"],
        start: Distortion::Division { kappa: 0.0 },
        export_formats: &["json", "halcon"],
        wide_angle: false,
    },
    LensModel {
        name: "kannala_brandt",
        aliases: &[],
        label: "Kannala-Brandt (fisheye)",
        description: "Kannala-Brandt fisheye (OpenCV fisheye, Kalibr equidistant)",
        coefficients: &["k1", "k2", "k3", "k4"],
        start: Distortion::KannalaBrandt {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            k4: 0.0,
        },
        export_formats: &[
            "json",
            "opencv-yaml (cv2.fisheye)",
            "opencv-xml (cv2.fisheye)",
            "ros-yaml (equidistant)",
            "kalibr (equidistant)",
        ],
        wide_angle: true,
    },
    LensModel {
        name: "eucm",
        aliases: &[],
        label: "EUCM",
        description: "Enhanced unified camera model (EUCM, wide angle)",
        coefficients: &["alpha", "beta"],
        start: Distortion::Eucm {
            alpha: 0.5,
            beta: 1.0,
        },
        export_formats: &["json", "kalibr (eucm)"],
        wide_angle: true,
    },
    LensModel {
        name: "none",
        aliases: &[],
        label: "none",
        description: "Pinhole, no distortion",
        coefficients: &[],
        start: Distortion::None,
        export_formats: ALL_CAMERA_FORMATS,
        wide_angle: false,
    },
    LensModel {
        name: "tilted",
        aliases: &[
            ("scheimpflug", "a Scheimpflug camera's tilted sensor"),
            ("opencv14", "OpenCV's 14 coefficients"),
        ],
        label: "Scheimpflug (tilted sensor)",
        description: "Scheimpflug / tilted sensor: OpenCV rational + thin prism + tilt tau_x tau_y (CALIB_TILTED_MODEL, laser profilers)",
        coefficients: &[
            "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tau_x",
            "tau_y",
        ],
        start: Distortion::Tilted {
            k1: 0.0,
            k2: 0.0,
            k3: 0.0,
            k4: 0.0,
            k5: 0.0,
            k6: 0.0,
            p1: 0.0,
            p2: 0.0,
            s1: 0.0,
            s2: 0.0,
            s3: 0.0,
            s4: 0.0,
            tau_x: 0.0,
            tau_y: 0.0,
        },
        export_formats: &["json", "opencv-yaml", "opencv-xml"],
        wide_angle: false,
    },
    // Its coefficients (`dx0 dy0 dx1 ...`, two per control point) come
    // with the layout: the start has none and the calibration makes
    // `2 nx ny` of them (`--spline-knots`, `--spline-order`).
    LensModel {
        name: "splined",
        aliases: &[(
            "splined_stereographic",
            "a stereographic projection with a B-spline correction",
        )],
        label: "splined stereographic",
        description: "Splined stereographic (a B-spline correction over a grid of knots, after mrcal; fits lenses no parametric model does)",
        coefficients: &[],
        start: Distortion::Splined(Spline {
            order: splined::DEFAULT_ORDER,
            nx: splined::DEFAULT_KNOTS.0,
            ny: splined::DEFAULT_KNOTS.1,
            u_max: [0.0, 0.0],
            smoothness: splined::DEFAULT_SMOOTHNESS,
            control: Vec::new(),
        }),
        export_formats: &["json"],
        wide_angle: false,
    },
];

/// The names of [`LENS_MODELS`], in menu order.
pub static MODEL_NAMES: [&str; N_MODELS] = {
    let mut names = [""; N_MODELS];
    let mut i = 0;
    while i < names.len() {
        names[i] = LENS_MODELS[i].name;
        i += 1;
    }
    names
};

impl LensModel {
    /// The model called `name` or one of its aliases; `None` for an unknown
    /// name (say which are known with [`model_list`]).
    pub fn named(name: &str) -> Option<&'static LensModel> {
        let all: &'static [LensModel] = &LENS_MODELS;
        all.iter()
            .find(|m| m.name == name || m.aliases.iter().any(|(a, _)| *a == name))
    }

    /// The coefficients the solvers start from, in the order of
    /// [`LensModel::coefficients`].
    pub fn start_values(&self) -> Vec<f64> {
        self.start.coefficients()
    }

    /// The export formats without their conditions (`kalibr`, not `kalibr
    /// (with k3 held at 0)`).
    pub fn format_names(&self) -> impl Iterator<Item = &'static str> {
        self.export_formats
            .iter()
            .map(|f| f.split(" (").next().unwrap_or(f))
    }
}

impl Distortion {
    /// The model called `name` (see [`LensModel::named`]: `brown5` is
    /// another name for `brown`) with the coefficients the solvers start
    /// from; `None` for an unknown name.
    pub fn named(name: &str) -> Option<Distortion> {
        LensModel::named(name).map(|m| m.start.clone())
    }
}

/// The model names as a message lists them: `brown, radial_k1_k2_k5, ...,
/// none`.
pub fn model_list() -> String {
    MODEL_NAMES.join(", ")
}

/// The help of a `--model` option whose models are those of `subject`
/// ("the camera", "both cameras"): every name of the table, the default's
/// coefficients and aliases.
pub fn model_help(subject: &str) -> String {
    let names: Vec<String> = LENS_MODELS
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let mut notes = Vec::new();
            if i == 0 {
                notes.push(format!("default: {}", m.coefficients.join(" ")));
            }
            notes.extend(
                m.aliases
                    .iter()
                    .map(|(alias, means)| format!("also called {alias}, {means}")),
            );
            if notes.is_empty() {
                m.name.to_string()
            } else {
                format!("{} ({})", m.name, notes.join("; "))
            }
        })
        .collect();
    format!("Lens model of {subject}: {}", names.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use wasm_bindgen_test::wasm_bindgen_test;

    /// Each row is its variant: the name, the coefficient names and the
    /// start values' count agree with [`Distortion`]; every model of the
    /// examples (one per variant) has a row; names and aliases are unique.
    #[wasm_bindgen_test(unsupported = test)]
    fn every_row_is_its_variant_and_every_variant_has_a_row() {
        for m in &LENS_MODELS {
            assert_eq!(m.start.model_name(), m.name, "row {}", m.name);
            assert_eq!(
                m.start.coefficient_names(),
                m.coefficients,
                "row {}",
                m.name
            );
            assert_eq!(
                m.start_values().len(),
                m.coefficients.len(),
                "row {}",
                m.name
            );
            assert!(!m.export_formats.is_empty(), "{} exports nowhere", m.name);
            assert_eq!(
                m.export_formats[0], "json",
                "{}: JSON holds every model",
                m.name
            );
        }
        for example in Camera::examples() {
            let name = example.distortion.model_name();
            let row = LensModel::named(name).unwrap_or_else(|| panic!("{name} has no row"));
            assert_eq!(row.name, name);
        }
        let mut all: Vec<&str> = LENS_MODELS
            .iter()
            .flat_map(|m| std::iter::once(m.name).chain(m.aliases.iter().map(|a| a.0)))
            .collect();
        let n = all.len();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), n, "a name or alias is used twice");
    }

    #[wasm_bindgen_test(unsupported = test)]
    fn names_aliases_and_the_texts_made_from_the_table() {
        assert_eq!(
            model_list(),
            "brown, radial_k1_k2_k5, rational, division, kannala_brandt, eucm, none, tilted, splined"
        );
        assert_eq!(
            Distortion::named("brown5"),
            Distortion::named("brown"),
            "brown5 is brown"
        );
        assert_eq!(
            Distortion::named("eucm"),
            Some(Distortion::Eucm {
                alpha: 0.5,
                beta: 1.0
            })
        );
        assert_eq!(Distortion::named("fisheye"), None);
        assert_eq!(
            model_help("the camera"),
            "Lens model of the camera: brown (default: k1 k2 p1 p2 k3; also called brown5, \
             OpenCV's 5 coefficients), radial_k1_k2_k5, rational, division, kannala_brandt, \
             eucm, none, tilted (also called scheimpflug, a Scheimpflug camera's tilted sensor; \
             also called opencv14, OpenCV's 14 coefficients), \
             splined (also called splined_stereographic, a stereographic projection \
             with a B-spline correction)"
        );
        assert_eq!(
            Distortion::named("scheimpflug"),
            Distortion::named("tilted")
        );
        assert_eq!(Distortion::named("opencv14"), Distortion::named("tilted"));
        let kb = LensModel::named("kannala_brandt").map(|m| m.format_names().collect::<Vec<_>>());
        assert_eq!(
            kb,
            Some(vec![
                "json",
                "opencv-yaml",
                "opencv-xml",
                "ros-yaml",
                "kalibr"
            ])
        );
    }
}
