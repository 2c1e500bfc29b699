//! The frame's compositing in lanes: the rays of a band as a structure of arrays of 32-bit lanes
//! ([`RayLanes`]), and `Compos::step_coded` of the frame's two modes (`FrontToBack`, `Max`) on a
//! row of them as straight-line code ([`LaneRules`]), so that a row of samples costs no
//! data-dependent branch (`docs/numerics/frame.md`, "The model's fast path").
//!
//! Why the lanes hold a frame's coxels exactly: every frame coxel starts as `Coxel::empty` (no
//! geometry: `z = Znone`, geometry colour 0) and the compositing unit never writes `z` or the
//! geometry colour outside `Flush`, which the frame never sends; so a frame coxel is its `R, G, B,
//! A` and its terminated flag. `R, G, B` are saturated to `chan_max < 2^29` at every write
//! (`AccW <= 28`), and `A` stays at most `one = 2^AccW` (rule 5 adds at most `1 - A`; `Max` writes
//! a corrected alpha `<= 2^Q` on the `2^AccW` scale). The products (`t a`, `w c`) are taken in 64
//! bits, as `Compos::step_coded` takes them.

use crate::units::cube5_compos::{CodedSample, Compos, ComposMode, Coxel};

/// The coxels of a band: lane `n` is coxel `n` (row-major, the band's rows).
pub(super) struct RayLanes {
    pub c: [Vec<u32>; 3],
    pub a: Vec<u32>,
    /// 1: the ray is terminated.
    pub term: Vec<u32>,
    /// The counts of the rows composited so far (shaded, without effect, after termination),
    /// per lane of a row: added lane by lane, summed once at the band's end (a sum per row cost
    /// three horizontal additions).
    pub counts: [[u32; LANES]; 3],
}

/// Lanes of the widest row ([`RayLanes::counts`]).
pub(super) const LANES: usize = 8;

impl RayLanes {
    /// `len` empty coxels.
    pub fn new(len: usize) -> Self {
        Self {
            c: std::array::from_fn(|_| vec![0; len]),
            a: vec![0; len],
            term: vec![0; len],
            counts: [[0; LANES]; 3],
        }
    }

    /// The counts of every row composited so far.
    pub fn row_counts(&self) -> RowCounts {
        let sum = |k: &[u32; LANES]| k.iter().map(|&x| u64::from(x)).sum::<u64>();
        RowCounts {
            shaded: sum(&self.counts[0]),
            without_effect: sum(&self.counts[1]),
            after_termination: sum(&self.counts[2]),
        }
    }

    /// The coxels, each `init` (the frame's `Coxel::empty`) with the lanes' `R, G, B, A` and flag:
    /// every one of `out` written.
    pub fn write(&self, init: &Coxel, out: &mut [std::mem::MaybeUninit<Coxel>]) {
        for (n, x) in out.iter_mut().enumerate() {
            x.write(Coxel {
                rgba: [
                    u64::from(self.c[0][n]),
                    u64::from(self.c[1][n]),
                    u64::from(self.c[2][n]),
                    u64::from(self.a[n]),
                ],
                terminated: self.term[n] != 0,
                ..*init
            });
        }
    }
}

/// What a row of samples did (the sweep's counts, `SweepStats`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct RowCounts {
    pub shaded: u64,
    pub without_effect: u64,
    pub after_termination: u64,
}

/// The compositing unit's constants of one slice of a frame, for its two modes on lanes.
#[derive(Debug, Clone, Copy)]
pub(super) struct LaneRules {
    mode: ComposMode,
    /// `AccW` (the coxel's scale `2^f`) and `Q` (the corrected alpha's).
    f: u32,
    q: u32,
    one: u32,
    chan_max: u32,
    et: u32,
    /// The slice's depth fails the depth test (`depth >= Znone`, every frame coxel's `z`):
    /// rule 4 leaves every coxel unchanged.
    past: bool,
    /// `ColorW` (a colour code's width).
    cw: u32,
    /// `rnd`'s halves `2^(AccW - 1)` and `2^(Q - 1)`, and `!past` as a lane factor (made once a
    /// slice rather than once a block).
    half_f: u64,
    half_q: u64,
    open: u32,
    /// The two products of rule 5 in 32-bit lanes ([`rnd_mul32`]), when the widths allow it
    /// (`narrow_products`): the weight `rnd(t a, Q)` split at `Q`, and a colour's term
    /// `rnd(w c, AccW)` as `rnd(w (c >> col_k), col_g)`.
    narrow: bool,
    col_k: u32,
    col_g: u32,
    /// `unit_code(c, ColorW, AccW)` from `e = expand_double(c)` as `((e << up) + half) >> down`:
    /// `e 2^(AccW - 2 ColorW)` when `AccW >= 2 ColorW` (`down = 0`, `half = 0`), else `rnd(e, 2
    /// ColorW - AccW)` (`up = 0`).
    code_shifts: (u32, u32, u32),
}

/// `rnd(x y, s) = floor((x y + 2^(s-1)) / 2^s)` in 32 bits, for `1 <= s <= 16`, `y <= 2^s` and `x
/// y / 2^s + 1 < 2^32`: with `x = xh 2^s + xl` (`xl < 2^s`), `x y + 2^(s-1) = xh y 2^s + (xl y +
/// 2^(s-1))`, and the first term is a multiple of `2^s`, so the quotient is `xh y + floor((xl y +
/// 2^(s-1)) / 2^s)`; `xl y + 2^(s-1) <= (2^s - 1) 2^s + 2^(s-1) < 2^(2s) <= 2^32`. No 64-bit
/// product, so AVX2 takes eight lanes a multiply (`vpmulld`) instead of four (`vpmuludq`) and no
/// narrowing shuffle.
#[inline(always)]
fn rnd_mul32(x: u32, y: u32, s: u32) -> u32 {
    let m = (1u32 << s) - 1;
    (x >> s) * y + (((x & m) * y + (1 << (s - 1))) >> s)
}

/// Whether rule 5's products fit [`rnd_mul32`], and the colour term's shift and split `(k, g)`.
/// The weight: `t <= 2^AccW`, `a <= 2^Q`, split at `Q <= 16`. A colour's term `rnd(w c, AccW)`
/// with `w <= 2^AccW`, `c <= 2^AccW`: split at `AccW` when `AccW <= 16` (`k = 0`); otherwise, when
/// `AccW >= 2 ColorW` and `2 ColorW <= 16`, a code is `expand_double(c) 2^k` with `k = AccW - 2
/// ColorW` (`Compos::code`, `colour_codes`), and `rnd(w e 2^k, g + k) = rnd(w e, g)` (`g = 2
/// ColorW`; `(w e + 2^(g-1)) 2^k` over `2^(g+k)`), `e <= 2^g`. Otherwise 64-bit products.
fn narrow_products(f: u32, q: u32, cw: u32) -> Option<(u32, u32)> {
    if q == 0 || q > 16 || f == 0 {
        return None;
    }
    if f <= 16 {
        Some((0, f))
    } else if f >= 2 * cw && 2 * cw <= 16 && cw >= 1 {
        Some((f - 2 * cw, 2 * cw))
    } else {
        None
    }
}

impl LaneRules {
    /// The rules of `compos` in `mode` (`FrontToBack` or `Max`: `None` otherwise) for samples of
    /// depth `depth` against frame coxels (`z = Znone`).
    pub fn new(compos: &Compos, mode: ComposMode, depth: u32) -> Option<Self> {
        let cfg = compos.config();
        if !matches!(mode, ComposMode::FrontToBack | ComposMode::Max)
            || cfg.acc_w > 29
            || cfg.q() == 0
        {
            return None;
        }
        Some(Self {
            mode,
            f: cfg.acc_w,
            q: cfg.q(),
            one: cfg.one() as u32,
            chan_max: cfg.chan_max() as u32,
            cw: cfg.color_w,
            et: compos.regs().et_threshold.min(u64::from(u32::MAX)) as u32,
            past: depth >= cfg.z_none(),
            half_f: 1 << (cfg.acc_w - 1),
            half_q: 1 << (cfg.q() - 1),
            open: u32::from(depth < cfg.z_none()),
            narrow: narrow_products(cfg.acc_w, cfg.q(), cfg.color_w).is_some(),
            col_k: narrow_products(cfg.acc_w, cfg.q(), cfg.color_w).map_or(0, |p| p.0),
            col_g: narrow_products(cfg.acc_w, cfg.q(), cfg.color_w).map_or(1, |p| p.1),
            code_shifts: if cfg.acc_w >= 2 * cfg.color_w {
                (cfg.acc_w - 2 * cfg.color_w, 0, 0)
            } else {
                let k = 2 * cfg.color_w - cfg.acc_w;
                (0, k, 1 << (k - 1))
            },
        })
    }

    /// `Compos::code`'s colour codes (`c_w`, `unit_code(c, ColorW, AccW)` of each channel) of
    /// colours `c[ch][n] <= 2^ColorW - 1`, in 32-bit lanes: `expand_double(c, ColorW) <=
    /// 2^(2 ColorW) <= 2^24` (`ColorW <= 12`), and the code is at most `2^AccW <= 2^28`.
    #[inline(always)]
    pub fn colour_codes<const N: usize>(&self, c: &[[u32; N]; 3]) -> [[u32; N]; 3] {
        let w = self.cw;
        let (up, down, half) = self.code_shifts;
        let expand = |c: u32| c * ((1 << w) + 1) + (c >> (w - 1));
        // One formula for both cases (`code_shifts`), so that the lanes take it straight, with
        // no branch whose two results the compiler would merge lane by lane.
        let mut out = [[0u32; N]; 3];
        for ch in 0..3 {
            for n in 0..N {
                out[ch][n] = ((expand(c[ch][n]) << up) + half) >> down;
            }
        }
        out
    }

    /// Whether `Compos::leaves_unchanged_corrected` holds at corrected alpha `am` for every coxel
    /// of lanes `at .. at + N` (so for every smaller alpha: it is monotone in the alpha).
    #[inline(always)]
    pub fn all_unchanged<const N: usize>(&self, st: &RayLanes, at: usize, am: u64) -> bool {
        let a: &[u32; N] = st.a[at..at + N].try_into().expect("N lanes");
        let term: &[u32; N] = st.term[at..at + N].try_into().expect("N lanes");
        // Per lane 1 when the coxel is kept; their AND, branch-free so that it compiles to lanes.
        let mut keep = 1u32;
        match self.mode {
            ComposMode::FrontToBack => {
                if self.past || am == 0 {
                    // Rule 5 adds nothing: only rule 3 can change a coxel below the threshold.
                    let et = self.et;
                    for i in 0..N {
                        keep &= u32::from(term[i] != 0) | u32::from(a[i] < et);
                    }
                } else {
                    // A sample above alpha 0 changes every coxel that is not terminated.
                    for &t in term {
                        keep &= u32::from(t != 0);
                    }
                }
            }
            _ => {
                if self.past {
                    return true;
                }
                // `am <= 2^Q`, so on the coxel's scale it is at most `2^AccW`.
                let aw = (am << (self.f - self.q)) as u32;
                for i in 0..N {
                    keep &= u32::from(term[i] != 0) | u32::from(aw <= a[i]);
                }
            }
        }
        keep != 0
    }

    /// Whether a sample of corrected alpha `sa[n]` would change any of lanes `at .. at + N` (rule
    /// 5 writes the coxel, or rule 3 terminates it): `!Compos::leaves_unchanged_corrected` for
    /// some lane whose ray is not terminated. The sweep shades a row only then.
    #[inline(always)]
    pub fn any_changes<const N: usize>(&self, st: &RayLanes, at: usize, sa: &[u32; N]) -> bool {
        let a: &[u32; N] = st.a[at..at + N].try_into().expect("N lanes");
        let term: &[u32; N] = st.term[at..at + N].try_into().expect("N lanes");
        // Per lane 1 when the sample changes the coxel; their OR, branch-free (lanes).
        let mut any = 0u32;
        let open = |i: usize| u32::from(term[i] == 0);
        let before = 1 - u32::from(self.past);
        match self.mode {
            ComposMode::FrontToBack => {
                let et = self.et;
                for i in 0..N {
                    any |= open(i) & (u32::from(a[i] >= et) | (before & u32::from(sa[i] != 0)));
                }
            }
            _ => {
                let sh = self.f - self.q;
                for i in 0..N {
                    any |= open(i) & before & u32::from((sa[i] << sh) > a[i]);
                }
            }
        }
        any != 0
    }

    /// `Compos::step_coded` of the samples `sa[n]` (corrected alpha) and `sc[ch][n]` (colour
    /// codes on the coxel's scale) onto lanes `at .. at + N`, in this slice's mode; the colours
    /// of a sample that changes nothing are not read. Returns the sweep's counts of the row.
    #[cfg(test)]
    pub fn step<const N: usize>(
        &self,
        st: &mut RayLanes,
        at: usize,
        sa: &[u32; N],
        sc: &[[u32; N]; 3],
    ) -> RowCounts {
        let k = self.step_lanes::<N>(st, at, sa, sc);
        let sum = |k: &[u32; N]| k.iter().map(|&x| u64::from(x)).sum::<u64>();
        RowCounts {
            shaded: sum(&k[0]),
            without_effect: sum(&k[1]),
            after_termination: sum(&k[2]),
        }
    }

    /// [`LaneRules::step`], its counts added to `st.counts` lane by lane (`N <= LANES`).
    #[inline(always)]
    pub fn step_counted<const N: usize>(
        &self,
        st: &mut RayLanes,
        at: usize,
        sa: &[u32; N],
        sc: &[[u32; N]; 3],
    ) {
        let k = self.step_lanes::<N>(st, at, sa, sc);
        for (acc, k) in st.counts.iter_mut().zip(&k) {
            for n in 0..N {
                acc[n] += k[n];
            }
        }
    }

    /// [`LaneRules::step`]'s work: per lane the samples shaded, without effect, after termination
    /// (`FrontToBack`: 1 or 0 a lane; `Max`: the row's sums in lane 0).
    #[inline(always)]
    fn step_lanes<const N: usize>(
        &self,
        st: &mut RayLanes,
        at: usize,
        sa: &[u32; N],
        sc: &[[u32; N]; 3],
    ) -> [[u32; N]; 3] {
        // Each way loads, computes and stores the lanes itself: one set of lanes merged from two
        // ways was split into scalar registers. (No closures: a closure's body is compiled without
        // the AVX2 of the sweep's copy when it is not inlined.)
        let (mut c, mut a, mut term) = load_lanes::<N>(st, at);
        let lanes = (&mut c, &mut a, &mut term);
        match self.mode {
            // One loop per product width, so that each is straight-line code over the lanes.
            ComposMode::FrontToBack if self.narrow => {
                let k = self.front_to_back::<N, true>(lanes, sa, sc);
                store_lanes(st, at, (&c, &a, &term));
                k
            }
            ComposMode::FrontToBack => {
                let k = self.front_to_back::<N, false>(lanes, sa, sc);
                store_lanes(st, at, (&c, &a, &term));
                k
            }
            _ => {
                // `Max` sums its counts itself (per-lane flags made its lanes scalar code): the
                // sums go to lane 0.
                let k = self.max::<N>(lanes, sa, sc);
                store_lanes(st, at, (&c, &a, &term));
                let mut out = [[0u32; N]; 3];
                for (o, k) in out.iter_mut().zip(k) {
                    o[0] = k;
                }
                out
            }
        }
    }

    /// Rule 5 of `Max` (with rules 1 and 4) on lanes `c`, `a`, `term`; returns the counts
    /// (shaded, without effect, after termination).
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn max<const N: usize>(
        &self,
        (c, a, term): (&mut [[u32; N]; 3], &mut [u32; N], &mut [u32; N]),
        sa: &[u32; N],
        sc: &[[u32; N]; 3],
    ) -> [u32; 3] {
        let (sh, open) = (self.f - self.q, self.open);
        let (mut shaded, mut none_n, mut after) = (0u32, 0u32, 0u32);
        for i in 0..N {
            let t = term[i];
            let aw = sa[i] << sh;
            // The sample replaces the coxel when it is above it. As a lane mask (`&` of flags,
            // not `&&`, and selects by masks: no branch).
            let wins = u32::from(t == 0) & open & u32::from(aw > a[i]);
            let m = 0u32.wrapping_sub(wins);
            for ch in 0..3 {
                c[ch][i] = (sc[ch][i] & m) | (c[ch][i] & !m);
            }
            a[i] = (aw & m) | (a[i] & !m);
            after += u32::from(t != 0);
            none_n += u32::from(t == 0) & (wins ^ 1);
            shaded += wins;
        }
        [shaded, none_n, after]
    }
}

/// Lanes `at .. at + N` of `st`: colours, alpha, flag.
#[inline(always)]
fn load_lanes<const N: usize>(st: &RayLanes, at: usize) -> ([[u32; N]; 3], [u32; N], [u32; N]) {
    let lanes = |v: &Vec<u32>| -> [u32; N] { v[at..at + N].try_into().expect("N lanes") };
    (st.c.each_ref().map(lanes), lanes(&st.a), lanes(&st.term))
}

/// [`load_lanes`]'s lanes written back.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn store_lanes<const N: usize>(
    st: &mut RayLanes,
    at: usize,
    (c, a, term): (&[[u32; N]; 3], &[u32; N], &[u32; N]),
) {
    for (v, c) in st.c.iter_mut().zip(c) {
        v[at..at + N].copy_from_slice(c);
    }
    st.a[at..at + N].copy_from_slice(a);
    st.term[at..at + N].copy_from_slice(term);
}

impl LaneRules {
    /// Rule 5 of `FrontToBack` (with rules 1, 3 and 4) on lanes `c`, `a`, `term`; returns the
    /// per lane 1 where the sample was shaded, without effect, after termination. `NARROW`: the two products in 32 bits
    /// ([`rnd_mul32`], `narrow_products`), else in 64 as `Compos::step_coded` takes them.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn front_to_back<const N: usize, const NARROW: bool>(
        &self,
        (c, a, term): (&mut [[u32; N]; 3], &mut [u32; N], &mut [u32; N]),
        sa: &[u32; N],
        sc: &[[u32; N]; 3],
    ) -> [[u32; N]; 3] {
        let (f, q) = (self.f, self.q);
        let (et, one, chan_max) = (self.et, self.one, self.chan_max);
        let (half_f, half_q) = (self.half_f, self.half_q);
        let (k, g) = (self.col_k, self.col_g);
        // Rule 4 (past the depth) gives every lane the weight 0.
        let open = self.open;
        let [mut shaded, mut none_n, mut after] = [[0u32; N]; 3];
        for i in 0..N {
            let (a_in, t) = (a[i], term[i]);
            // Rule 1 (terminated) and rule 3 (at the threshold): no weight. Rule 5 otherwise; a
            // zero alpha gives a zero weight, which adds 0 to channels already saturated. Only
            // the products need more than 32 bits (or `rnd_mul32`'s split): the weight `w` is at
            // most `2^AccW`, a colour's term at most `2^AccW`, so a channel's sum stays below
            // `2^(AccW + 2) <= 2^31` before the saturation.
            let live = (t == 0) & (a_in < et);
            let wt = (u32::from(live) & open) * (one - a_in.min(one));
            // `rnd(x, s)` with `s >= 1` (`Q >= 1`, `AccW >= 1`).
            let w = if NARROW {
                rnd_mul32(wt, sa[i], q)
            } else {
                ((u64::from(wt) * u64::from(sa[i]) + half_q) >> q) as u32
            };
            for ch in 0..3 {
                let add = if NARROW {
                    rnd_mul32(w, sc[ch][i] >> k, g)
                } else {
                    ((u64::from(w) * u64::from(sc[ch][i]) + half_f) >> f) as u32
                };
                c[ch][i] = (c[ch][i] + add).min(chan_max);
            }
            let a_out = a_in + w;
            a[i] = a_out;
            term[i] = t | u32::from(a_out >= et);
            let none = live & (self.past | (sa[i] == 0));
            after[i] = u32::from(t != 0);
            none_n[i] = u32::from(none);
            shaded[i] = u32::from(t == 0) & u32::from(!none);
        }
        [shaded, none_n, after]
    }
}

/// The coded sample's colours as lanes (`c_w` on the coxel's scale, `<= 2^AccW`).
#[inline(always)]
pub(super) fn colours(s: &CodedSample) -> [u32; 3] {
    s.c_w.map(|c| c as u32)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{seed, thresholds};
    use super::*;
    use crate::units::cube5_compos::{ComposConfig, ComposRegs, OpacityLut, Sample};
    use rand::{Rng, SeedableRng};

    /// The lanes' colour codes are `Compos::code`'s, every colour of the narrow, default and wide
    /// widths and of `ColorW` 12 on `AccW` 12 (rounded) and 28 (shifted).
    #[test]
    fn colour_codes_are_the_compositing_units() {
        for cfg in [
            ComposConfig::NARROW,
            ComposConfig::DEFAULT,
            ComposConfig::WIDE,
            ComposConfig::new(12, 12, 0, 12, 16).unwrap(),
            ComposConfig::new(12, 12, 6, 28, 16).unwrap(),
        ] {
            let regs = ComposRegs::defaults(&cfg);
            let c = Compos::new(cfg, OpacityLut::new(1.0, &cfg).unwrap(), regs).unwrap();
            let rules = LaneRules::new(&c, ComposMode::FrontToBack, 0).unwrap();
            for v in 0..=cfg.color_max() {
                let want = colours(&c.code(&Sample {
                    rgb: [v; 3],
                    alpha: 0,
                    depth: 0,
                    mode: ComposMode::FrontToBack,
                }));
                assert_eq!(
                    rules.colour_codes(&[[v]; 3]),
                    want.map(|x| [x]),
                    "{cfg:?} {v}"
                );
            }
        }
    }

    /// `rnd_mul32` is the 64-bit `rnd(x y, s)` at every split `s` it allows, at the extremes
    /// (`x` up to `2^28`, `y` up to `2^s`) and at random.
    #[test]
    fn products_in_32_bits_are_the_64_bit_ones() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 8);
        for s in 1..=16u32 {
            let rnd = |x: u32, y: u32| ((u64::from(x) * u64::from(y) + (1 << (s - 1))) >> s) as u32;
            let ys = [0, 1, (1 << s) - 1, 1 << s];
            let xs = [0, 1, (1 << s) - 1, 1 << s, (1 << 28) - 1, 1 << 28];
            for &x in &xs {
                for &y in &ys {
                    assert_eq!(rnd_mul32(x, y, s), rnd(x, y), "{x} {y} {s}");
                }
            }
            for _ in 0..20_000 {
                let (x, y) = (rng.random_range(0..=1 << 28), rng.random_range(0..=1 << s));
                assert_eq!(rnd_mul32(x, y, s), rnd(x, y), "{x} {y} {s}");
            }
        }
        // Which widths take them: the default (`AccW` 20 over `2 ColorW` 16) and the narrow do,
        // `ColorW` 10 on `AccW` 24 does not.
        assert_eq!(narrow_products(20, 16, 8), Some((4, 16)));
        assert_eq!(narrow_products(8, 8, 8), Some((0, 8)));
        assert_eq!(narrow_products(24, 12, 10), None);
        assert_eq!(narrow_products(20, 17, 8), None);
    }

    /// The lanes' rules equal `Compos::step_coded` and `Compos::leaves_unchanged_corrected` on
    /// frame coxels (any reachable `R, G, B, A` and flag, `z = Znone`, no geometry): random
    /// coxels and samples, both modes, depths before and past `Znone`, the narrow, default and
    /// wide widths, thresholds 0, the default and disabled.
    #[test]
    fn lanes_equal_the_compositing_unit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed() + 7);
        for cfg in [
            ComposConfig::NARROW,
            ComposConfig::DEFAULT,
            ComposConfig::WIDE,
            ComposConfig::new(12, 12, 6, 28, 16).unwrap(),
            // The 32-bit products at their edges: `AccW = 16 = Q` (split at 16), and `AccW = 17`
            // over `2 ColorW = 16` (codes `expand_double(c) 2`).
            ComposConfig::new(8, 12, 4, 16, 12).unwrap(),
            ComposConfig::new(8, 10, 6, 17, 12).unwrap(),
        ] {
            let one = cfg.one();
            for regs in thresholds(&cfg) {
                let ratio = rng.random_range(0.3..3.0);
                let c = Compos::new(cfg, OpacityLut::new(ratio, &cfg).unwrap(), regs).unwrap();
                let init = Coxel::empty(&cfg);
                for mode in [ComposMode::FrontToBack, ComposMode::Max] {
                    for _ in 0..400 {
                        let depth = match rng.random_range(0..4) {
                            0 => cfg.z_none(),
                            _ => rng.random_range(0..cfg.z_none()),
                        };
                        let rules = LaneRules::new(&c, mode, depth).unwrap();
                        const N: usize = 8;
                        let n = N;
                        let coxels: Vec<Coxel> = (0..n)
                            .map(|_| {
                                let a = match rng.random_range(0..4) {
                                    0 => 0,
                                    1 => one,
                                    2 => regs.et_threshold.min(one),
                                    _ => rng.random_range(0..=one),
                                };
                                Coxel {
                                    rgba: [0, 1, 2]
                                        .map(|_| match rng.random_range(0..3) {
                                            0 => cfg.chan_max(),
                                            _ => rng.random_range(0..=cfg.chan_max()),
                                        })
                                        .into_iter()
                                        .chain([a])
                                        .collect::<Vec<_>>()
                                        .try_into()
                                        .unwrap(),
                                    terminated: rng.random_bool(0.2),
                                    ..init
                                }
                            })
                            .collect();
                        let samples: Vec<CodedSample> = (0..n)
                            .map(|_| {
                                let alpha = match rng.random_range(0..3) {
                                    0 => 0,
                                    _ => rng.random_range(0..=cfg.alpha_max()),
                                };
                                c.code(&Sample {
                                    rgb: std::array::from_fn(|_| {
                                        rng.random_range(0..=cfg.color_max())
                                    }),
                                    alpha,
                                    depth,
                                    mode,
                                })
                            })
                            .collect();
                        let mut st = RayLanes::new(n);
                        for (i, x) in coxels.iter().enumerate() {
                            for ch in 0..3 {
                                st.c[ch][i] = x.rgba[ch] as u32;
                            }
                            st.a[i] = x.rgba[3] as u32;
                            st.term[i] = u32::from(x.terminated);
                        }
                        let sa: [u32; N] = std::array::from_fn(|i| samples[i].a as u32);
                        let sc: [[u32; N]; 3] = std::array::from_fn(|ch| {
                            std::array::from_fn(|i| colours(&samples[i])[ch])
                        });
                        // The block test at the largest alpha of the row.
                        let am = samples.iter().map(|s| s.a).max().unwrap();
                        let want_all = coxels
                            .iter()
                            .all(|x| c.leaves_unchanged_corrected(x, am, depth, mode));
                        assert_eq!(rules.all_unchanged::<N>(&st, 0, am), want_all, "{mode:?}");
                        // And lane by lane.
                        for (i, x) in coxels.iter().enumerate() {
                            let want = c.leaves_unchanged_corrected(x, am, depth, mode);
                            assert_eq!(rules.all_unchanged::<1>(&st, i, am), want, "{mode:?}");
                        }
                        let mut want = RowCounts::default();
                        let mut any = false;
                        for (i, (x, s)) in coxels.iter().zip(&samples).enumerate() {
                            let unchanged = c.leaves_unchanged_corrected(x, s.a, depth, mode);
                            if x.terminated {
                                want.after_termination += 1;
                            } else if unchanged {
                                want.without_effect += 1;
                            } else {
                                want.shaded += 1;
                            }
                            let changes = !x.terminated && !unchanged;
                            assert_eq!(
                                rules.any_changes::<1>(&st, i, &[sa[i]]),
                                changes,
                                "{mode:?} {x:?} {s:?}"
                            );
                            any |= changes;
                        }
                        assert_eq!(rules.any_changes::<N>(&st, 0, &sa), any, "{mode:?}");
                        // Eight lanes at once, and one at a time.
                        let mut one_by_one = RayLanes::new(n);
                        for (d, s) in one_by_one.c.iter_mut().zip(&st.c) {
                            d.copy_from_slice(s);
                        }
                        one_by_one.a.copy_from_slice(&st.a);
                        one_by_one.term.copy_from_slice(&st.term);
                        let got = rules.step::<N>(&mut st, 0, &sa, &sc);
                        assert_eq!(got, want, "{mode:?}");
                        let mut sum = RowCounts::default();
                        for i in 0..n {
                            let k = rules.step::<1>(
                                &mut one_by_one,
                                i,
                                &[sa[i]],
                                &[[sc[0][i]], [sc[1][i]], [sc[2][i]]],
                            );
                            sum.shaded += k.shaded;
                            sum.without_effect += k.without_effect;
                            sum.after_termination += k.after_termination;
                        }
                        assert_eq!(sum, want, "{mode:?}");
                        for lanes in [&st, &one_by_one] {
                            let mut out = vec![std::mem::MaybeUninit::uninit(); n];
                            lanes.write(&init, &mut out);
                            // SAFETY: `write` wrote every element.
                            let out: Vec<Coxel> = out
                                .into_iter()
                                .map(|x| unsafe { x.assume_init() })
                                .collect();
                            for (i, (x, s)) in coxels.iter().zip(&samples).enumerate() {
                                assert_eq!(
                                    out[i],
                                    c.step_coded(x, s),
                                    "{cfg:?} {regs:?} {mode:?} depth {depth}: {x:?} {s:?}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
