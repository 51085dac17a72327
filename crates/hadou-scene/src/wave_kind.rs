//! The kinds of `[[wave]]`: the one place their names live. Every `match` over [`WaveKind`] or
//! [`CurveKind`] in the workspace is exhaustive (no catch-all arm), so a new kind is a compile
//! error at each place that must handle it; ARCHITECTURE.md's "Add a wave shape" lists them.

/// A `[[wave]] kind`: a field whose line integral has a closed form (hadou_math::energy), or a
/// curve integrated numerically along its centre line (hadou_math::curve, 002 §3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WaveKind {
    /// `"sphere"`: the field `α_s / |P − M|` (002 eq. 3.4).
    Sphere,
    /// `"cylinder"`: the field around an infinite line (002 eq. 3.5).
    Cylinder,
    /// `"capsule"`: the straight beam, a segment with spheres at its ends (002 eq. 3.11).
    Capsule,
    /// `"beam"`: the bulged beam, a capsule with extra sphere fields at head and muzzle (SPEC.md §1.2).
    Beam,
    /// A curve (see [`CurveKind`]).
    Curve(CurveKind),
}

/// The curved kinds: a centre line `O + x·D + y(x)·up + z(x)·(D × up)` (002 §3.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CurveKind {
    /// `"helix"`: a spiral of radius `radius` and angular rate `rate`.
    Helix,
    /// `"trig"`: sums of sines across the axis (`y_terms`, `z_terms`).
    Trig,
    /// `"bezier"`: a Bézier curve of any degree through `points`.
    Bezier,
    /// `"bspline"`: a B-spline of `order` over `points` (and optional `knots`).
    BSpline,
}

/// Keys of every `[[wave]]`.
const WAVE_COMMON: &[&str] = &[
    "name",
    "kind",
    "rgba",
    "falloff",
    "core_radius",
    "light_ramp",
    "light_ramp_kind",
    "light_ramp_smoothing",
    "light_glow",
    "wind",
];
/// Keys of every closed-form kind (sphere, cylinder, capsule, beam) beyond their own.
const ANALYTIC_COMMON: &[&str] = &["j"];
/// Keys of every curve beyond its shape's own.
const CURVE_COMMON: &[&str] =
    &["O", "D", "up", "alpha", "gamma", "k", "j", "field", "integrator", "m", "n", "epsilon"];

impl WaveKind {
    /// Every kind, in the order of docs/scene-format.md.
    pub const ALL: [WaveKind; 8] = [
        WaveKind::Sphere,
        WaveKind::Cylinder,
        WaveKind::Capsule,
        WaveKind::Beam,
        WaveKind::Curve(CurveKind::Helix),
        WaveKind::Curve(CurveKind::Trig),
        WaveKind::Curve(CurveKind::Bezier),
        WaveKind::Curve(CurveKind::BSpline),
    ];

    /// The kind's name in a scene file (`kind = "…"`).
    pub const fn name(self) -> &'static str {
        match self {
            WaveKind::Sphere => "sphere",
            WaveKind::Cylinder => "cylinder",
            WaveKind::Capsule => "capsule",
            WaveKind::Beam => "beam",
            WaveKind::Curve(CurveKind::Helix) => "helix",
            WaveKind::Curve(CurveKind::Trig) => "trig",
            WaveKind::Curve(CurveKind::Bezier) => "bezier",
            WaveKind::Curve(CurveKind::BSpline) => "bspline",
        }
    }

    /// The kind named `name`, if there is one.
    pub fn from_name(name: &str) -> Option<WaveKind> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether the kind is a curve (integrated numerically) rather than a closed-form shape.
    pub const fn is_curve(self) -> bool {
        match self {
            WaveKind::Sphere | WaveKind::Cylinder | WaveKind::Capsule | WaveKind::Beam => false,
            WaveKind::Curve(_) => true,
        }
    }

    /// Whether the kind is a segment `M → M + length·D` (or `M → M2`) with a head: what the
    /// viewer draws a head handle for and the firing preset grows.
    pub const fn is_segment(self) -> bool {
        match self {
            WaveKind::Capsule | WaveKind::Beam => true,
            WaveKind::Sphere | WaveKind::Cylinder | WaveKind::Curve(_) => false,
        }
    }

    /// Every key a `[[wave]]` of this kind accepts: every wave's, every closed-form shape's or
    /// every curve's, and [`Self::own_keys`].
    pub fn keys(self) -> Vec<&'static str> {
        let group = if self.is_curve() { CURVE_COMMON } else { ANALYTIC_COMMON };
        WAVE_COMMON.iter().chain(group).chain(self.own_keys()).copied().collect()
    }

    /// The keys of the kind's own (beyond those every wave, every closed-form shape or every
    /// curve has), as `[[wave]]` accepts them.
    pub const fn own_keys(self) -> &'static [&'static str] {
        match self {
            WaveKind::Sphere => &["M", "alpha_s"],
            WaveKind::Cylinder => &["M", "D", "alpha_c"],
            WaveKind::Capsule => &["M", "M2", "D", "length", "alpha_s", "alpha_c"],
            WaveKind::Beam => &["M", "M2", "D", "length", "alpha_s", "alpha_c", "head_alpha", "muzzle_alpha"],
            WaveKind::Curve(CurveKind::Helix) => &["radius", "rate", "phase", "length"],
            WaveKind::Curve(CurveKind::Trig) => &["rate", "y_terms", "z_terms", "length"],
            WaveKind::Curve(CurveKind::Bezier) => &["points"],
            WaveKind::Curve(CurveKind::BSpline) => &["points", "order", "knots"],
        }
    }
}

/// A value of a new wave's key (see [`WaveKind::starter`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StarterValue {
    /// The point the wave is added at.
    At,
    /// Two units before that point along x, where a wave travelling along +x starts.
    Behind,
    /// A fixed vector.
    Vector([f32; 3]),
    /// A number.
    Number(f32),
    /// A list of `[y, z]` pairs.
    Pairs(&'static [[f32; 2]]),
}

/// What the viewer's firing preset animates for a kind (see [`WaveKind::growth`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Growth {
    /// The segment grows from its muzzle: `M → M2` when the wave has `M2`, else `length` from 0.
    Segment,
    /// The strength key rises from 0 to its value.
    Strength(&'static str),
    /// The reach `k` (the part of the curve drawn) from 0.001 to 1.
    Reach,
}

impl WaveKind {
    /// The keys and values of a new wave of this kind, visible at a typical scene scale (the
    /// viewer's "add wave"); `name`, `kind` and `rgba` are every wave's.
    pub const fn starter(self) -> &'static [(&'static str, StarterValue)] {
        use StarterValue::{At, Behind, Number, Pairs, Vector};
        const X: StarterValue = Vector([1.0, 0.0, 0.0]);
        const POINTS: StarterValue = Pairs(&[[0.0, 0.0], [1.0, 0.0], [-1.0, 0.5], [0.0, 0.0]]);
        match self {
            WaveKind::Sphere => &[("M", At), ("alpha_s", Number(0.1))],
            WaveKind::Cylinder => &[("M", At), ("D", X), ("alpha_c", Number(0.05))],
            WaveKind::Capsule => &[
                ("M", Behind),
                ("D", X),
                ("length", Number(4.0)),
                ("alpha_s", Number(0.08)),
                ("alpha_c", Number(0.08)),
            ],
            WaveKind::Beam => &[
                ("M", Behind),
                ("D", X),
                ("length", Number(4.0)),
                ("alpha_s", Number(0.08)),
                ("alpha_c", Number(0.08)),
                ("head_alpha", Number(0.1)),
            ],
            WaveKind::Curve(CurveKind::Helix) => &[
                ("O", Behind),
                ("D", X),
                ("alpha", Number(0.05)),
                ("radius", Number(0.5)),
                ("rate", Number(6.0)),
                ("length", Number(4.0)),
            ],
            WaveKind::Curve(CurveKind::Trig) => &[
                ("O", Behind),
                ("D", X),
                ("alpha", Number(0.05)),
                ("rate", Number(3.0)),
                ("y_terms", Pairs(&[[0.5, 0.0]])),
                ("length", Number(4.0)),
            ],
            WaveKind::Curve(CurveKind::Bezier | CurveKind::BSpline) => &[
                ("O", Behind),
                ("D", X),
                ("alpha", Number(0.05)),
                ("gamma", Number(4.0)),
                ("points", POINTS),
            ],
        }
    }

    /// What firing a wave of this kind animates.
    pub const fn growth(self) -> Growth {
        match self {
            WaveKind::Capsule | WaveKind::Beam => Growth::Segment,
            WaveKind::Sphere => Growth::Strength("alpha_s"),
            WaveKind::Cylinder => Growth::Strength("alpha_c"),
            WaveKind::Curve(_) => Growth::Reach,
        }
    }
}

/// The kind names of `[[wave]] kind`, in the order of [`WaveKind::ALL`].
pub const WAVE_KINDS: &[&str] = &{
    let mut names = [""; WaveKind::ALL.len()];
    let mut i = 0;
    while i < names.len() {
        names[i] = WaveKind::ALL[i].name();
        i += 1;
    }
    names
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_are_unique() {
        for k in WaveKind::ALL {
            assert_eq!(WaveKind::from_name(k.name()), Some(k));
        }
        let mut names = WAVE_KINDS.to_vec();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), WaveKind::ALL.len());
        assert_eq!(WaveKind::from_name("cone"), None);
    }

    /// A new wave's keys are keys its kind accepts (the scene reader's own table, or those of
    /// every curve), and what firing animates is one of them.
    #[test]
    fn starter_keys_are_the_kinds_keys() {
        for k in WaveKind::ALL {
            for (key, _) in k.starter() {
                assert!(k.keys().contains(key), "{}: {key}", k.name());
            }
            if let Growth::Strength(key) = k.growth() {
                assert!(k.starter().iter().any(|(s, _)| *s == key), "{}: {key}", k.name());
            }
        }
    }
}
