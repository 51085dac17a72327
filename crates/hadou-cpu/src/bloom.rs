//! The `[bloom]` on the CPU: `hadou_math::bloom`'s glare chain over a band of rows, each level's
//! rows filled in parallel (every texel from the same texels in the same order, so the picture is
//! the same for any number of threads), every level from the first downsample on in eight lanes
//! (`hadou_math::bloom::lanes`, the same planes bit for bit on every vector path), the last
//! upsample and the streak at level 1 (half the resolution), and the bilinear glare, the
//! composite and the colour mapping in one pass over the band (eight pixels at a time).

use hadou_math::bloom::{self, BloomParams, Plane, PlanePool, RowFill};
use hadou_math::shade;
use hadou_math::simd::{dispatch, Lane, SimdPath, WithLanes};
use hadou_scene::{Frame, ToneMode};
use rayon::prelude::*;
use std::ops::Range;

/// Fills a plane's rows with rayon.
struct Parallel;

/// Planes of fewer texels than this are filled on the calling thread: the pyramid's small levels
/// cost less than handing their rows to other threads.
const SMALL_PLANE: usize = 1 << 14;

impl RowFill for Parallel {
    fn fill(&self, plane: &mut Plane, f: &(dyn Fn(usize, &mut [[f32; 3]]) + Sync)) {
        if plane.data.len() < SMALL_PLANE {
            return bloom::Sequential.fill(plane, f);
        }
        let (w, y0) = (plane.width, plane.rows.start);
        plane.data.par_chunks_mut(w).enumerate().for_each(|(r, row)| f(y0 + r, row));
    }

    fn fill_blocks(&self, a: &mut Plane, b: Option<&mut Plane>, block: usize, f: &bloom::BlockFn<'_>) {
        if a.data.len() < SMALL_PLANE {
            return bloom::Sequential.fill_blocks(a, b, block, f);
        }
        let (y0, wa, block) = (a.rows.start, a.width, block.max(1));
        let rows = |i: usize, len: usize| y0 + i * block..y0 + i * block + len / wa;
        match b {
            Some(b) => {
                let wb = b.width;
                a.data
                    .par_chunks_mut(wa * block)
                    .zip(b.data.par_chunks_mut(wb * block))
                    .enumerate()
                    .for_each(|(i, (ca, cb))| f(rows(i, ca.len()), ca, cb));
            }
            None => {
                a.data
                    .par_chunks_mut(wa * block)
                    .enumerate()
                    .for_each(|(i, ca)| f(rows(i, ca.len()), ca, &mut []));
            }
        }
    }
}

/// The rows of the linear image the band `band` (non-empty) of `frame` needs under `params`: the
/// band and the bloom's halo ([`bloom::Plan`]).
pub(crate) fn source_rows(frame: &Frame, params: &BloomParams, band: Range<usize>) -> Range<usize> {
    bloom::source_rows(params, frame.width as usize, frame.height as usize, band)
}

/// The band `band` of `linear` (which holds [`source_rows`]) with the glare added and the frame's
/// colour mapping applied, into `color` (`band.len()` rows); the glare's levels on the vector
/// path `simd`, its planes from `pool` (and given back to it). After the glare's plane at level 1 ([`bloom::lanes::try_glare_plane`]), each row
/// of the band is read once: its bilinear glare, the composite and the mapping in one pass.
pub(crate) fn glare_and_map(
    frame: &Frame,
    params: &BloomParams,
    linear: &Plane,
    band: Range<usize>,
    color: &mut [[f32; 4]],
    simd: SimdPath,
    pool: &mut PlanePool,
) -> Result<(), hadou_scene::RenderError> {
    let g = bloom::lanes::try_glare_plane_in(simd, params, linear, band.clone(), &Parallel, pool).map_err(
        |bytes| {
            hadou_scene::RenderError::Memory(format!(
                "the glare's planes need {:.2} GB that could not be allocated",
                bytes as f64 / 1e9
            ))
        },
    )?;
    let mode = frame.color_mapping.mode;
    let w = linear.width;
    color.par_chunks_mut(w.max(1)).enumerate().for_each_init(Vec::new, |row, (r, out)| {
        let y = band.start + r;
        row.resize(w, [0.0; 3]);
        bloom::lanes::upsample_composite_row(simd, &g, y, linear.row(y), row);
        dispatch(simd, MapRow { mode, linear: row, out });
    });
    pool.give(g);
    Ok(())
}

/// The colour mapping of a row of linear colour, eight pixels at a time (`shade`'s lane mappings:
/// lane for lane the values of the scalar ones).
struct MapRow<'a> {
    mode: ToneMode,
    linear: &'a [[f32; 3]],
    out: &'a mut [[f32; 4]],
}

impl WithLanes for MapRow<'_> {
    type Output = ();
    #[inline(always)]
    fn run<L: Lane>(self) {
        for (c, o) in self.linear.chunks(8).zip(self.out.chunks_mut(8)) {
            // The channels as lanes (zeros past the row's end).
            let mut ch = [[0.0f32; 8]; 3];
            for (i, p) in c.iter().enumerate() {
                ch[0][i] = p[0];
                ch[1][i] = p[1];
                ch[2][i] = p[2];
            }
            let v = [L::from_array(ch[0]), L::from_array(ch[1]), L::from_array(ch[2])];
            let m = match self.mode {
                ToneMode::Faithful => shade::map_faithful_lanes(v),
                ToneMode::Filmic => shade::map_filmic_lanes(v),
            };
            let (r, g, b) = (m[0].to_array(), m[1].to_array(), m[2].to_array());
            for (i, px) in o.iter_mut().enumerate() {
                *px = [r[i], g[i], b[i], 1.0];
            }
        }
    }
}
