//! [`Frame::shadow_casts`]: the one place both backends get each shadow's projection directions
//! and shadow-map frames from, evaluated on a frame's objects, waves and `[[shadow]]`s.

use crate::bounds::{object_bounds, object_center};
use crate::frame::{Frame, LightLine};
use crate::shadow::{ShadowCast, ShadowLight, ShadowMethod};
use hadou_math::shadow::{horizon_fade, wave_direction, MapFrame};
use hadou_math::{Vec3, Vec3f};

impl Frame {
    /// Every projection this frame's shadows make, in shadow order, then caster order: each with
    /// its direction `k` (the sun's direction, or [`wave_direction`] from the nearest point of the
    /// wave's light line `lines[wave]` to the caster's centre), its effective opacity, and for a
    /// map its frame. Casts that cannot show (opacity 0, a light at or below the receivers'
    /// horizon, a wave with no strength, casters without triangles) are left out.
    pub fn shadow_casts(&self, lines: &[LightLine]) -> Vec<ShadowCast> {
        let mut out = Vec::new();
        for (si, s) in self.shadows.iter().enumerate() {
            if s.opacity <= 0.0 {
                continue;
            }
            let mut push = |casters: Vec<u32>, k: Vec3f| {
                let opacity = s.opacity * horizon_fade(k, s.up);
                if opacity <= 0.0 || casters.is_empty() {
                    return;
                }
                let map = match s.method {
                    ShadowMethod::Plane(_) => None,
                    ShadowMethod::Map { .. } => {
                        let mut lo = Vec3::splat(f32::INFINITY);
                        let mut hi = Vec3::splat(f32::NEG_INFINITY);
                        for &c in &casters {
                            if let Some((a, b)) = object_bounds(&self.objects[c as usize]) {
                                lo = lo.min(a);
                                hi = hi.max(b);
                            }
                        }
                        if !(lo.is_finite() && hi.is_finite()) {
                            return;
                        }
                        Some(MapFrame::new(k, (lo + hi) * 0.5, (hi - lo).length() * 0.5))
                    }
                };
                out.push(ShadowCast { shadow: si as u32, casters, k, opacity, map });
            };
            match s.light {
                ShadowLight::Sun(l) => {
                    let casters = s
                        .casters
                        .iter()
                        .copied()
                        .filter(|&c| object_center(&self.objects[c as usize]).is_some());
                    push(casters.collect(), l);
                }
                ShadowLight::Wave { wave, theta } => {
                    let (Some(w), Some(line)) = (self.waves.get(wave as usize), lines.get(wave as usize))
                    else {
                        continue;
                    };
                    if w.light_strength() <= 0.0 {
                        continue;
                    }
                    for &c in &s.casters {
                        let Some(b) = object_center(&self.objects[c as usize]) else { continue };
                        let k = wave_direction(b, line.nearest(b), s.up, theta);
                        push(vec![c], k);
                    }
                }
            }
        }
        out
    }
}
