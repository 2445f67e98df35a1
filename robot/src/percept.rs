//! What the perception stages found in one cycle, kept by type: a stage puts its own output
//! type ([`Percept`]), and the controller, the estimates record and the experiments read it by
//! that type. A stage with a new kind of output defines the type in its own file; nothing else
//! changes.
//!
//! ```
//! use omniloop_robot::{Percept, Percepts};
//!
//! /// A reading a stage of one's own gives.
//! #[derive(Debug, Clone, PartialEq)]
//! struct Brightness(f64);
//!
//! impl Percept for Brightness {
//!     fn record(&self) -> Option<(&'static str, serde_json::Value)> {
//!         Some(("brightness", self.0.into()))
//!     }
//! }
//!
//! let mut found = Percepts::default();
//! found.put(Brightness(0.5));
//! assert_eq!(found.get::<Brightness>(), Some(&Brightness(0.5)));
//! let keys: Vec<&str> = found.records().map(|(key, _)| key).collect();
//! assert_eq!(keys, ["brightness"]);
//! ```

use std::any::Any;
use std::fmt;

/// A kind of stage output. The type itself is the key: one value of each type a cycle.
pub trait Percept: Any + Send + Sync + fmt::Debug + Clone + PartialEq {
    /// Its entry in the estimates record (`estimates.jsonl`), a key and a value, or `None`
    /// (the default) when it is not recorded there.
    fn record(&self) -> Option<(&'static str, serde_json::Value)> {
        None
    }
}

/// What the map keeps of a [`Percept`]: the same type, behind a pointer.
trait Stored: Any + Send + Sync + fmt::Debug {
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
    fn into_any(self: Box<Self>) -> Box<dyn Any>;
    fn clone_box(&self) -> Box<dyn Stored>;
    fn same(&self, other: &dyn Stored) -> bool;
    fn record(&self) -> Option<(&'static str, serde_json::Value)>;
}

impl<T: Percept> Stored for T {
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn into_any(self: Box<Self>) -> Box<dyn Any> {
        self
    }
    fn clone_box(&self) -> Box<dyn Stored> {
        Box::new(self.clone())
    }
    fn same(&self, other: &dyn Stored) -> bool {
        other.as_any().downcast_ref::<T>() == Some(self)
    }
    fn record(&self) -> Option<(&'static str, serde_json::Value)> {
        Percept::record(self)
    }
}

/// The outputs of a cycle's stages, one of each type, in the order the stages put them.
#[derive(Debug, Default)]
pub struct Percepts {
    items: Vec<Box<dyn Stored>>,
}

impl Percepts {
    /// None yet.
    pub const fn new() -> Self {
        Self { items: Vec::new() }
    }

    /// Keeps `value`, in place of the one of its type already kept.
    pub fn put<T: Percept>(&mut self, value: T) {
        match self.get_mut::<T>() {
            Some(old) => *old = value,
            None => self.items.push(Box::new(value)),
        }
    }

    /// The output of type `T`, if a stage gave one.
    pub fn get<T: Percept>(&self) -> Option<&T> {
        self.items
            .iter()
            .find_map(|p| p.as_ref().as_any().downcast_ref::<T>())
    }

    /// The output of type `T`, to change.
    pub fn get_mut<T: Percept>(&mut self) -> Option<&mut T> {
        self.items
            .iter_mut()
            .find_map(|p| p.as_mut().as_any_mut().downcast_mut::<T>())
    }

    /// Takes the output of type `T` out.
    pub fn take<T: Percept>(&mut self) -> Option<T> {
        let at = self
            .items
            .iter()
            .position(|p| p.as_ref().as_any().is::<T>())?;
        self.items
            .remove(at)
            .into_any()
            .downcast::<T>()
            .ok()
            .map(|b| *b)
    }

    /// The entries the outputs give the estimates record, in the order they were put.
    pub fn records(&self) -> impl Iterator<Item = (&'static str, serde_json::Value)> + '_ {
        self.items.iter().filter_map(|p| p.record())
    }

    /// How many outputs there are.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether no stage gave any.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

impl Clone for Percepts {
    fn clone(&self) -> Self {
        Self {
            items: self.items.iter().map(|p| p.clone_box()).collect(),
        }
    }
}

impl PartialEq for Percepts {
    /// The same outputs, in the same order.
    fn eq(&self, other: &Self) -> bool {
        self.items.len() == other.items.len()
            && self
                .items
                .iter()
                .zip(&other.items)
                .all(|(a, b)| a.same(b.as_ref()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Clone, PartialEq)]
    struct A(u32);
    impl Percept for A {}

    #[derive(Debug, Clone, PartialEq)]
    struct B(&'static str);
    impl Percept for B {
        fn record(&self) -> Option<(&'static str, serde_json::Value)> {
            Some(("b", self.0.into()))
        }
    }

    #[test]
    fn outputs_are_kept_and_read_by_type() {
        let mut p = Percepts::default();
        assert!(p.get::<A>().is_none());
        p.put(B("x"));
        p.put(A(1));
        p.put(A(2));
        assert_eq!(p.len(), 2, "a second A replaces the first");
        assert_eq!(p.get::<A>(), Some(&A(2)));
        if let Some(a) = p.get_mut::<A>() {
            a.0 = 3;
        }
        let copy = p.clone();
        assert_eq!(copy, p);
        assert_eq!(p.take::<A>(), Some(A(3)));
        assert_ne!(copy, p);
        assert!(p.get::<A>().is_none());
        let records: Vec<_> = p.records().collect();
        assert_eq!(records, [("b", serde_json::Value::from("x"))]);
    }
}
