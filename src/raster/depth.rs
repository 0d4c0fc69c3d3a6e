//! The depth buffer.
//!
//! **Convention: depth is NDC z in [0, 1], 0 at the near plane, 1 at the far plane;
//! smaller is nearer.** The buffer clears to 1.0 and the default test is `Less`.
//!
//! Seed 000's pseudo code stores `Depth = 1 / (1/z)` (the view distance) and writes when
//! `DepthBuffer < Depth`, which keeps the *farthest* surface: the comparison only makes
//! sense if the buffer held 1/z (larger = nearer). This crate stores z_ndc, which is
//! affine in screen space (exact to interpolate with screen-space barycentrics, no
//! divide), and compares with `<`.

/// When a fragment passes the depth test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum DepthFunc {
    /// Nearer than what is stored.
    Less,
    /// Nearer or equal (later draws win ties).
    LessEqual,
    /// Always (painter's order).
    Always,
}

impl DepthFunc {
    /// Whether `new` passes against the stored `old`.
    #[must_use]
    #[inline(always)]
    pub fn passes(self, new: f32, old: f32) -> bool {
        match self {
            DepthFunc::Less => new < old,
            DepthFunc::LessEqual => new <= old,
            DepthFunc::Always => true,
        }
    }

    /// Symbol for the inspector.
    #[must_use]
    pub fn symbol(self) -> &'static str {
        match self {
            DepthFunc::Less => "<",
            DepthFunc::LessEqual => "<=",
            DepthFunc::Always => "always",
        }
    }
}

/// Depth test and write configuration of a draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DepthState {
    pub func: DepthFunc,
    pub write: bool,
}

impl DepthState {
    /// No test and no write: the draw never touches the depth buffer (and a frame
    /// whose draws are all like this needs none).
    pub const OFF: DepthState = DepthState {
        func: DepthFunc::Always,
        write: false,
    };

    /// Whether a draw with this state reads or writes the depth buffer.
    #[must_use]
    #[inline(always)]
    pub fn uses_buffer(self) -> bool {
        self != Self::OFF
    }
}

impl Default for DepthState {
    fn default() -> Self {
        Self {
            func: DepthFunc::Less,
            write: true,
        }
    }
}

/// Value of a cleared depth buffer: the far plane.
pub const DEPTH_CLEAR: f32 = 1.0;

/// An f32 depth buffer.
#[derive(Clone, Debug, PartialEq)]
pub struct DepthBuffer {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
}

impl DepthBuffer {
    /// A cleared buffer.
    #[must_use]
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            data: vec![DEPTH_CLEAR; width as usize * height as usize],
        }
    }

    /// Clears to the far plane, resizing only if the size changed.
    pub fn reset(&mut self, width: u32, height: u32) {
        self.width = width;
        self.height = height;
        self.data.clear();
        self.data
            .resize(width as usize * height as usize, DEPTH_CLEAR);
    }

    /// Depth at a pixel.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> f32 {
        self.data[y as usize * self.width as usize + x as usize]
    }
}
