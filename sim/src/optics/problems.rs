//! Collecting the numbers of an optics table that break a rule, by key.

/// The keys of a table at fault and why, in the order found.
#[derive(Debug, Default)]
pub struct Problems(pub Vec<(&'static str, String)>);

impl Problems {
    /// Key `key` breaks a rule.
    pub fn fail(&mut self, key: &'static str, why: impl Into<String>) {
        self.0.push((key, why.into()));
    }

    /// Key `key` must be a finite number > 0.
    pub fn positive(&mut self, key: &'static str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(key, format!("must be a finite number > 0 (got {v})"));
        }
    }
}
