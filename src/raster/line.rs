//! The midpoint (Bresenham) line algorithm (`docs/rasterization.md`), in all eight
//! octants, with an
//! optional step-by-step trace and exact clipping.
//!
//! # Conventions
//!
//! * Endpoints are integer pixels; every pixel between them is drawn, endpoints
//!   included: `max(|Δx|, |Δy|) + 1` pixels.
//! * The line is reduced to the first-octant case by reflections: the
//!   endpoints are swapped so the major axis is walked increasing, x and y are swapped
//!   for steep lines (|Δy| > |Δx|), and the minor axis is flipped for negative slopes.
//!   In that frame `dx ≥ dy ≥ 0`, `d₀ = 2dy − dx`, `incrE = 2dy`,
//!   `incrNE = 2(dy − dx)`, and each step adds one of them: **E** (stay on the minor
//!   coordinate) when `d ≤ 0`, else **NE**. A midpoint exactly on the line (`d = 0`)
//!   therefore stays on the start's minor coordinate, and A→B draws the same pixels as
//!   B→A (both walk from the same end).
//! * The loop always runs over the major axis of the reflected line (a common
//!   mistake swaps x and y but keeps looping over the old x range, so steep lines
//!   with negative slope never run).
//! * Closed form (used for clipping): the minor offset at step `k` is
//!   `y_k = ⌈(2k·dy − dx) / 2dx⌉` and the decision variable before step `k` is
//!   `d_k = 2dy(k+1) − 2dx·y_k − dx`. A clipped line starts its walk at the first step
//!   inside the target with that `d_k`, instead of walking in from outside.

/// Largest accepted |coordinate|: keeps every product in the closed forms within `i64`.
pub const MAX_LINE_COORD: i64 = 1 << 40;

/// A step of the reduced (first-octant) walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Move {
    /// Stay on the minor coordinate.
    E,
    /// Advance the minor coordinate.
    NE,
}

impl Move {
    /// The classic name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Move::E => "E",
            Move::NE => "NE",
        }
    }
}

/// A line reduced to the first octant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line {
    /// The endpoints as given.
    pub a: (i64, i64),
    pub b: (i64, i64),
    /// Octant of the direction a→b, 0..8, counted from +x towards +y (y-down screen
    /// space, so octant 0 goes right and slightly down): octant `o` covers directions
    /// between `o·45°` and `(o+1)·45°`.
    pub octant: u8,
    /// The walk starts at `b` (the major axis decreases from a to b).
    pub swap_ends: bool,
    /// x and y are swapped (steep line).
    pub swap_xy: bool,
    /// The minor axis is flipped (it decreases along the walk).
    pub flip_minor: bool,
    /// Major and minor extents in the reduced frame, `dx ≥ dy ≥ 0`.
    pub dx: i64,
    pub dy: i64,
    pub incr_e: i64,
    pub incr_ne: i64,
}

/// One step of a traced walk.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    /// Step index k (0 at the walk's start).
    pub k: i64,
    /// The pixel drawn at this step, in the original coordinates.
    pub pixel: (i64, i64),
    /// The decision variable before deciding, and the decision with the value after it;
    /// `None` at the last pixel, where the walk ends.
    pub decision: Option<(i64, Move, i64)>,
}

/// Receives the steps of a walk. `NoTrace` compiles to nothing.
pub trait Tracer {
    fn step(&mut self, s: Step);
}

/// Tracing off.
pub struct NoTrace;

impl Tracer for NoTrace {
    #[inline(always)]
    fn step(&mut self, _: Step) {}
}

impl Tracer for Vec<Step> {
    fn step(&mut self, s: Step) {
        self.push(s);
    }
}

/// Why a line was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("line coordinates must be within ±2^40")]
pub struct LineRangeError;

/// `⌈a / b⌉` for `b > 0`.
#[inline]
fn ceil_div(a: i64, b: i64) -> i64 {
    -((-a).div_euclid(b))
}

impl Line {
    /// Reduces the line a→b to the first octant.
    pub fn new(a: (i64, i64), b: (i64, i64)) -> Result<Self, LineRangeError> {
        if [a.0, a.1, b.0, b.1]
            .iter()
            .any(|c| c.abs() > MAX_LINE_COORD)
        {
            return Err(LineRangeError);
        }
        let (ddx, ddy) = (b.0 - a.0, b.1 - a.1);
        let swap_xy = ddy.abs() > ddx.abs();
        let (major, minor) = if swap_xy { (ddy, ddx) } else { (ddx, ddy) };
        let swap_ends = major < 0;
        let minor_walk = if swap_ends { -minor } else { minor };
        let (dx, dy) = (major.abs(), minor.abs());
        Ok(Self {
            a,
            b,
            octant: octant(ddx, ddy),
            swap_ends,
            swap_xy,
            flip_minor: minor_walk < 0,
            dx,
            dy,
            incr_e: 2 * dy,
            incr_ne: 2 * (dy - dx),
        })
    }

    /// The reflections that reduce this line to the first octant, in words
    /// (`none` if it is already there).
    #[must_use]
    pub fn reflections(&self) -> String {
        let names: Vec<&str> = [
            (self.swap_ends, "swap endpoints"),
            (self.swap_xy, "swap x and y"),
            (self.flip_minor, "flip minor axis"),
        ]
        .iter()
        .filter(|(on, _)| *on)
        .map(|(_, n)| *n)
        .collect();
        if names.is_empty() {
            "none".into()
        } else {
            names.join(", ")
        }
    }

    /// The walk's starting pixel.
    #[must_use]
    pub fn start(&self) -> (i64, i64) {
        if self.swap_ends { self.b } else { self.a }
    }

    /// Number of pixels, `max(|Δx|, |Δy|) + 1`.
    #[must_use]
    pub fn len(&self) -> i64 {
        self.dx + 1
    }

    /// Never empty: a line of zero length is its one endpoint.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Initial decision variable `d₀ = 2dy − dx`.
    #[must_use]
    pub fn d0(&self) -> i64 {
        2 * self.dy - self.dx
    }

    /// Minor offset at step k (closed form).
    #[must_use]
    pub fn minor_at(&self, k: i64) -> i64 {
        if self.dx == 0 {
            0
        } else {
            ceil_div(2 * k * self.dy - self.dx, 2 * self.dx)
        }
    }

    /// Decision variable before step k (closed form).
    #[must_use]
    pub fn d_at(&self, k: i64) -> i64 {
        2 * self.dy * (k + 1) - 2 * self.dx * self.minor_at(k) - self.dx
    }

    /// The original-coordinate pixel for reduced coordinates (major k, minor m).
    #[must_use]
    #[inline(always)]
    pub fn pixel(&self, k: i64, m: i64) -> (i64, i64) {
        let (sx, sy) = self.start();
        let m = if self.flip_minor { -m } else { m };
        if self.swap_xy {
            (sx + m, sy + k)
        } else {
            (sx + k, sy + m)
        }
    }

    /// The screen direction of a move, e.g. `+x+y` (y-down).
    #[must_use]
    pub fn direction(&self, mv: Move) -> &'static str {
        let m = i64::from(mv == Move::NE);
        let (dx, dy) = {
            let (a, b) = self.pixel(1, m);
            let (s0, s1) = self.start();
            (a - s0, b - s1)
        };
        match (dx, dy) {
            (1, 0) => "+x",
            (1, 1) => "+x+y",
            (0, 1) => "+y",
            (-1, 1) => "-x+y",
            (1, -1) => "+x-y",
            _ => "?",
        }
    }

    /// Walks steps `k0..=k1` (within `0..=dx`), starting the decision variable at
    /// `d_at(k0)`: one add per pixel.
    #[inline(always)]
    fn walk_range<P: FnMut(i64, i64), T: Tracer>(
        &self,
        k0: i64,
        k1: i64,
        mut plot: P,
        tracer: &mut T,
    ) {
        let mut m = self.minor_at(k0);
        let mut d = self.d_at(k0);
        for k in k0..=k1 {
            let (x, y) = self.pixel(k, m);
            plot(x, y);
            if k == self.dx {
                tracer.step(Step {
                    k,
                    pixel: (x, y),
                    decision: None,
                });
                break;
            }
            let before = d;
            let mv = if d <= 0 {
                d += self.incr_e;
                Move::E
            } else {
                d += self.incr_ne;
                m += 1;
                Move::NE
            };
            tracer.step(Step {
                k,
                pixel: (x, y),
                decision: Some((before, mv, d)),
            });
        }
    }

    /// Draws every pixel of the line.
    pub fn draw<P: FnMut(i64, i64), T: Tracer>(&self, plot: P, tracer: &mut T) {
        self.walk_range(0, self.dx, plot, tracer);
    }

    /// The range of steps whose pixels lie in `[0, w) × [0, h)`, computed in closed
    /// form; `None` if the line misses the target.
    #[must_use]
    pub fn clip_range(&self, w: i64, h: i64) -> Option<(i64, i64)> {
        let (sx, sy) = self.start();
        let (major0, minor0, major_size, minor_size) = if self.swap_xy {
            (sy, sx, h, w)
        } else {
            (sx, sy, w, h)
        };
        // Major axis: start + k ∈ [0, size).
        let mut k0 = (-major0).max(0);
        let mut k1 = (major_size - 1 - major0).min(self.dx);
        // Minor axis: start ± y_k ∈ [0, size), y_k non-decreasing in k.
        let (lo, hi) = if self.flip_minor {
            (minor0 - (minor_size - 1), minor0)
        } else {
            (-minor0, minor_size - 1 - minor0)
        };
        if self.dy == 0 {
            if lo > 0 || hi < 0 {
                return None;
            }
        } else {
            let (dx, dy) = (i128::from(self.dx), i128::from(self.dy));
            // y_k ≥ lo ⇔ k > (2dx(lo−1) + dx) / 2dy
            let first = (2 * dx * (i128::from(lo) - 1) + dx).div_euclid(2 * dy) + 1;
            // y_k ≤ hi ⇔ k ≤ (2dx·hi + dx) / 2dy
            let last = (2 * dx * i128::from(hi) + dx).div_euclid(2 * dy);
            k0 = k0.max(first.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64);
            k1 = k1.min(last.clamp(i128::from(i64::MIN), i128::from(i64::MAX)) as i64);
        }
        (k0 <= k1).then_some((k0, k1))
    }

    /// Draws the pixels of the line inside `[0, w) × [0, h)`: exactly those the
    /// unclipped walk would draw there, starting at the entry step.
    pub fn draw_clipped<P: FnMut(i64, i64), T: Tracer>(
        &self,
        w: i64,
        h: i64,
        plot: P,
        tracer: &mut T,
    ) {
        if let Some((k0, k1)) = self.clip_range(w, h) {
            self.walk_range(k0, k1, plot, tracer);
        }
    }
}

/// Octant of a direction in y-down screen space, counted from +x towards +y.
#[must_use]
pub fn octant(dx: i64, dy: i64) -> u8 {
    match (dx >= 0, dy >= 0, dx.abs() >= dy.abs()) {
        (true, true, true) => 0,
        (true, true, false) => 1,
        (false, true, false) => 2,
        (false, true, true) => 3,
        (false, false, true) => 4,
        (false, false, false) => 5,
        (true, false, false) => 6,
        (true, false, true) => 7,
    }
}
