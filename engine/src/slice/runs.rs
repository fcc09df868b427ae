//! The cells of two cube axes `(u, w)` that a set of points' `W × W` tap
//! windows reach, kept as one run of `u` per line `w`: the buffer layout of
//! the strip and column walks ([`crate::slice::strip`], [`crate::slice::column`]).

/// `j mod n`: a mask on a power-of-two side, else a remainder.
#[inline(always)]
pub(crate) fn wrap(n: usize, j: i64) -> usize {
    if n.is_power_of_two() {
        j as usize & (n - 1)
    } else {
        j.rem_euclid(n as i64) as usize
    }
}

/// The axis `held` and the other two, `u` before `w` in memory order, and
/// their element strides on a cube of side `n` (x fastest).
pub(crate) fn axes_and_strides(held: usize, n: usize) -> ([usize; 3], [usize; 3]) {
    let (u, w) = match held {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let axes = [held, u, w];
    (axes, axes.map(|a| n.pow(a as u32)))
}

/// The runs: line `l` (that is `w = w_min + l`, unwrapped) holds the cells
/// `u = lo[l] ..` at `off[l] .. off[l + 1]` of a buffer of [`Runs::total`]
/// cells.
#[derive(Default)]
pub(crate) struct Runs {
    pub(crate) w_min: i32,
    pub(crate) lo: Vec<i32>,
    hi: Vec<i32>,
    pub(crate) off: Vec<usize>,
}

impl Runs {
    /// Cover the windows whose first taps are `(ju, jw)`; `false` when
    /// there are none.
    pub(crate) fn cover<const W: usize>(
        &mut self,
        windows: impl Iterator<Item = (i32, i32)> + Clone,
    ) -> bool {
        let (Some(w_min), Some(w_max)) = (
            windows.clone().map(|(_, jw)| jw).min(),
            windows.clone().map(|(_, jw)| jw).max(),
        ) else {
            return false;
        };
        self.w_min = w_min;
        let lines = (w_max - w_min) as usize + W;
        self.lo.clear();
        self.lo.resize(lines, i32::MAX);
        self.hi.clear();
        self.hi.resize(lines, i32::MIN);
        for (ju, jw) in windows {
            let first = (jw - w_min) as usize;
            for l in first..first + W {
                self.lo[l] = self.lo[l].min(ju);
                self.hi[l] = self.hi[l].max(ju + W as i32 - 1);
            }
        }
        self.off.clear();
        let mut total = 0usize;
        for l in 0..lines {
            self.off.push(total);
            // A line no window reaches holds no run.
            total += (self.hi[l] as i64 - self.lo[l] as i64 + 1).max(0) as usize;
        }
        self.off.push(total);
        true
    }

    /// Lines covered.
    pub(crate) fn lines(&self) -> usize {
        self.lo.len()
    }

    /// Cells in all runs.
    pub(crate) fn total(&self) -> usize {
        self.off.last().copied().unwrap_or(0)
    }

    /// The first and last cell of line `l`'s run in the plane at offset 0
    /// of a cube of side `n` with `u` and `w` strides `su` and `sw`
    /// (indices wrapped), or `None` past the last line or on a line no
    /// window reaches.
    pub(crate) fn ends(&self, n: usize, su: usize, sw: usize, l: usize) -> Option<(usize, usize)> {
        let (lo, hi) = (*self.lo.get(l)?, *self.hi.get(l)?);
        if hi < lo {
            return None;
        }
        let line = wrap(n, self.w_min as i64 + l as i64) * sw;
        Some((
            line + wrap(n, lo as i64) * su,
            line + wrap(n, hi as i64) * su,
        ))
    }

    /// Where row `b` of the window at `(ju, jw)` starts in the buffer.
    #[inline(always)]
    pub(crate) fn start(&self, ju: i32, jw: i32, b: usize) -> usize {
        let l = (jw - self.w_min) as usize + b;
        self.off[l] + (ju - self.lo[l]) as usize
    }
}
