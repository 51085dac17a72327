//! The checks a [`Wave`] built outside a scene file passes before it is drawn ([`Wave::check`]):
//! the same ranges the scene reader enforces for the same keys, with the reader's constants, so
//! an engine (hadou-bevy) and a file reject the same values.

use crate::frame::{Wave, WaveShape};
use crate::limits::{ALPHA_MAX, ATTENUATION_MAX, COORD_MAX, DIR_MIN};
use hadou_math::energy::{BeamField, CapsuleField};
use hadou_math::Vec3f;

/// Why a wave cannot be drawn: the scene-file key of the bad value and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct WaveError {
    /// The `[[wave]]` key, e.g. `"rgba"`, `"core_radius"`, `"D"`, `"alpha_s"`.
    pub key: &'static str,
    /// What is wrong and what would be right.
    pub message: String,
}

impl std::fmt::Display for WaveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` {}", self.key, self.message)
    }
}

impl std::error::Error for WaveError {}

fn fail(key: &'static str, message: impl Into<String>) -> Result<(), WaveError> {
    Err(WaveError { key, message: message.into() })
}

fn point(key: &'static str, p: Vec3f) -> Result<(), WaveError> {
    if [p.x, p.y, p.z].iter().all(|v| v.is_finite() && v.abs() <= COORD_MAX) {
        Ok(())
    } else {
        fail(key, format!("must be finite and within ±{COORD_MAX:e} (got [{}, {}, {}])", p.x, p.y, p.z))
    }
}

fn direction(key: &'static str, d: Vec3f) -> Result<(), WaveError> {
    point(key, d)?;
    if f64::from(d.length()) > DIR_MIN {
        Ok(())
    } else {
        fail(key, "must be a non-zero direction")
    }
}

fn strength(key: &'static str, alpha: f32) -> Result<(), WaveError> {
    if (0.0..=ALPHA_MAX).contains(&alpha) {
        Ok(())
    } else {
        fail(key, format!("must be in [0, {ALPHA_MAX:e}] (got {alpha})"))
    }
}

fn non_negative(key: &'static str, v: f32) -> Result<(), WaveError> {
    if (0.0..=COORD_MAX).contains(&v) {
        Ok(())
    } else {
        fail(key, format!("must be finite and in [0, {COORD_MAX:e}] (got {v})"))
    }
}

fn capsule(c: &CapsuleField<f32>) -> Result<(), WaveError> {
    point("M", c.m)?;
    direction("D", c.d)?;
    non_negative("length", c.length)?;
    strength("alpha_s", c.alpha_s)?;
    strength("alpha_c", c.alpha_c)
}

fn beam(b: &BeamField<f32>) -> Result<(), WaveError> {
    capsule(&b.capsule)?;
    strength("head_alpha", b.head_alpha)?;
    strength("muzzle_alpha", b.muzzle_alpha)
}

impl Wave {
    /// Checks what the wave pass reads against the ranges the scene reader enforces for the
    /// same keys: `rgba` finite and ≥ 0 with alpha in [0, 1], `core_radius` in `[0, COORD_MAX]`,
    /// positions finite within `±COORD_MAX`, directions non-zero, lengths in `[0, COORD_MAX]`,
    /// strengths in `[0, ALPHA_MAX]`, the attenuation exponent `j` in `[0, ATTENUATION_MAX]`, and a
    /// curve's own checks (`CurveWave::validate`). The first failure is returned, naming its key.
    pub fn check(&self) -> Result<(), WaveError> {
        let [r, g, b, a] = self.color;
        if ![r, g, b, a].iter().all(|v| v.is_finite() && *v >= 0.0) || a > 1.0 {
            return fail(
                "rgba",
                format!("must be finite and ≥ 0, alpha in [0, 1] (got [{r}, {g}, {b}, {a}])"),
            );
        }
        non_negative("core_radius", self.core_radius)?;
        let j = self.attenuation;
        if !(0.0..=ATTENUATION_MAX).contains(&j) {
            return fail(
                "j",
                format!("the attenuation exponent must be in [0, {ATTENUATION_MAX}] (got {j})"),
            );
        }
        match &self.shape {
            WaveShape::Sphere(s) => {
                point("M", s.center)?;
                strength("alpha_s", s.alpha)
            }
            WaveShape::Cylinder(c) => {
                point("M", c.point)?;
                direction("D", c.dir)?;
                strength("alpha_c", c.alpha)
            }
            WaveShape::Capsule(c) => capsule(c),
            WaveShape::Beam(b) => beam(b),
            WaveShape::Curve(curve) => {
                strength("alpha", curve.alpha)?;
                curve.validate().map_err(|e| WaveError { key: e.field, message: e.message })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::Scene;
    use std::path::Path;

    fn scene(wave: &str) -> Result<Scene, String> {
        let text = format!("[camera]\nposition = [0, 0, 10]\n\n[[wave]]\nname = \"w\"\n{wave}\n");
        Scene::parse(&text, Path::new("check.toml")).map_err(|e| e.to_string())
    }

    /// Every wave of every example scene passes: the check is no stricter than the reader.
    #[test]
    fn example_scenes_pass() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes");
        let mut checked = 0;
        for entry in std::fs::read_dir(dir).expect("scenes/") {
            let path = entry.expect("entry").path();
            if path.extension().is_none_or(|e| e != "toml") {
                continue;
            }
            let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
            let d = scene.duration();
            for t in [0.0, 0.5 * d, d] {
                for w in &scene.at(t).waves {
                    w.check().unwrap_or_else(|e| panic!("{}: wave {} at {t} s: {e}", path.display(), w.name));
                    checked += 1;
                }
            }
        }
        assert!(checked > 50, "{checked} waves checked");
    }

    /// A value the reader refuses for a key, the check refuses naming the same key.
    #[test]
    fn the_reader_and_the_check_refuse_the_same_values() {
        let sphere = "kind = \"sphere\"\nM = [0, 0, 0]\nalpha_s = 1";
        let beam = "kind = \"beam\"\nM = [0, 0, 0]\nD = [1, 0, 0]\nlength = 2\nalpha_s = 1\nalpha_c = 1";
        for (wave, key, bad) in [
            (sphere, "alpha_s", format!("{:e}", 2.0 * super::ALPHA_MAX)),
            (sphere, "j", format!("{}", super::ATTENUATION_MAX + 1.0)),
            (sphere, "core_radius", "-0.5".to_string()),
            (beam, "head_alpha", "-1".to_string()),
            (beam, "length", format!("{:e}", 2.0 * super::COORD_MAX)),
        ] {
            let good = scene(wave).unwrap_or_else(|e| panic!("{wave}: {e}"));
            let mut frame_wave = good.at(0.0).waves[0].clone();
            assert_eq!(frame_wave.check(), Ok(()), "{wave}");
            // The wave's lines with `key` set to the bad value.
            let mut lines: Vec<String> =
                wave.lines().filter(|l| !l.starts_with(&format!("{key} ="))).map(str::to_string).collect();
            lines.push(format!("{key} = {bad}"));
            let refused = scene(&lines.join("\n")).expect_err("the reader refuses it");
            assert!(refused.contains(&format!("`{key}`")), "{key} = {bad}: {refused}");
            let value: f32 = bad.parse().expect("a number");
            match (&mut frame_wave.shape, key) {
                (_, "j") => frame_wave.attenuation = value,
                (_, "core_radius") => frame_wave.core_radius = value,
                (crate::WaveShape::Sphere(s), "alpha_s") => s.alpha = value,
                (crate::WaveShape::Beam(b), "head_alpha") => b.head_alpha = value,
                (crate::WaveShape::Beam(b), "length") => b.capsule.length = value,
                other => panic!("no case for {other:?}"),
            }
            assert_eq!(frame_wave.check().map_err(|e| e.key), Err(key), "{key} = {bad}");
        }
    }
}
