//! When the objects' clips end on the scene's clock: the viewer's timeline runs at least that
//! long, so a clip chosen on a scene without tracks still plays and scrubs through once.

use crate::scene::Scene;

impl Scene {
    /// The scene time at which every clip played on the scene's clock has run through once:
    /// the largest `animation_start + length / |animation_speed|` of the objects that play a clip
    /// (start and speed as they are at the end of the scene's tracks), 0 when none does. Clips
    /// whose time is `animation_time` (pinned, or animated by a track), speeds of 0 and
    /// non-finite ends do not count.
    pub fn clips_end(&self) -> f32 {
        let vals = self.values_at(self.duration());
        let mut end = 0.0f32;
        for o in &self.objects {
            let Some(motion) = &o.motion else { continue };
            let Some(clip) = motion.clip.as_deref() else { continue };
            let p = &o.params;
            let pinned = motion.pinned
                || p.find("animation_time").is_some_and(|a| self.tracks.iter().any(|t| t.offset == a.offset));
            let speed = p.f(&vals, "animation_speed").abs();
            if pinned || speed.is_nan() || speed == 0.0 {
                continue;
            }
            let e = p.f(&vals, "animation_start").max(0.0) + clip.duration / speed;
            if e.is_finite() {
                end = end.max(e);
            }
        }
        end
    }
}
