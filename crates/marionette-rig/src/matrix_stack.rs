//! The matrix stack: the one way forward kinematics is computed.

use glam::Mat4;

/// A stack of accumulated transforms. The top of an empty stack is the identity;
/// [`push`](Self::push) multiplies a matrix onto the current top (`top · m`), and
/// [`pop`](Self::pop) restores the previous top.
#[derive(Debug, Clone, Default)]
pub struct MatrixStack {
    stack: Vec<Mat4>,
}

impl MatrixStack {
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty stack whose storage is reserved for `depth` pushes.
    pub fn with_capacity(depth: usize) -> Self {
        Self { stack: Vec::with_capacity(depth) }
    }

    /// The accumulated transform (identity when empty).
    pub fn top(&self) -> Mat4 {
        self.stack.last().copied().unwrap_or(Mat4::IDENTITY)
    }

    /// Pushes `top · m` and returns it.
    pub fn push(&mut self, m: Mat4) -> Mat4 {
        let next = self.top() * m;
        self.stack.push(next);
        next
    }

    /// Removes the top; popping an empty stack is a no-op that returns `None`.
    pub fn pop(&mut self) -> Option<Mat4> {
        self.stack.pop()
    }

    pub fn depth(&self) -> usize {
        self.stack.len()
    }
}
