//! The end of a run at full resolution: a ring of the last samples, so memory is fixed by the
//! window's length, not the run's.

use std::collections::VecDeque;

/// The last `cap` samples (t, θ unwrapped, θ').
#[derive(Debug, Clone)]
pub struct Window {
    cap: usize,
    samples: VecDeque<[f64; 3]>,
}

impl Window {
    pub fn new(cap: usize) -> Self {
        Self {
            cap,
            samples: VecDeque::with_capacity(cap.min(1 << 16)),
        }
    }

    pub fn push(&mut self, sample: [f64; 3]) {
        if self.cap == 0 {
            return;
        }
        if self.samples.len() == self.cap {
            self.samples.pop_front();
        }
        self.samples.push_back(sample);
    }

    /// Oldest first.
    pub fn samples(&self) -> impl ExactSizeIterator<Item = &[f64; 3]> {
        self.samples.iter()
    }

    pub fn len(&self) -> usize {
        self.samples.len()
    }

    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_last_samples_in_order() {
        let mut w = Window::new(5);
        for i in 0..1000 {
            w.push([f64::from(i), 0.0, 0.0]);
        }
        let ts: Vec<f64> = w.samples().map(|s| s[0]).collect();
        assert_eq!(ts, [995.0, 996.0, 997.0, 998.0, 999.0]);
    }
}
