//! Pipelines cached by what makes them — the shaders, their specialization
//! constants and the fixed-function state — below the passes (after kajiya's
//! pipeline cache, which its passes ask by shader path): a pass asks for its
//! pipeline and gets the one already built for the same key. A cache lives as
//! long as its owner (a render's frame state), so each render builds its own.

use super::{Context, GraphicsDesc, Pipeline};
use crate::error::Result;
use std::collections::HashMap;
use std::hash::Hash;
use std::sync::{Arc, Mutex};

/// Values made once per key.
pub struct Memo<K, V> {
    map: Mutex<HashMap<K, V>>,
}

impl<K: Hash + Eq, V: Clone> Memo<K, V> {
    pub fn new() -> Self {
        Self {
            map: Mutex::new(HashMap::new()),
        }
    }

    /// The value of `key`, made by `make` the first time (a failure is not kept).
    pub fn get_or_try<E>(&self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<V, E> {
        let mut map = self.map.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(v) = map.get(&key) {
            return Ok(v.clone());
        }
        let v = make()?;
        map.insert(key, v.clone());
        Ok(v)
    }

    /// Every value it holds, in no order.
    pub fn values(&self) -> Vec<V> {
        let map = self.map.lock().unwrap_or_else(|e| e.into_inner());
        map.values().cloned().collect()
    }

    /// How many values it holds.
    pub fn len(&self) -> usize {
        self.map.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<K: Hash + Eq, V: Clone> Default for Memo<K, V> {
    fn default() -> Self {
        Self::new()
    }
}

/// What a pipeline is made from.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Key {
    Compute(String, Vec<u32>),
    /// The graphics description, every field (its `Debug` form).
    Graphics(String),
}

/// A render's pipelines, each built once per (shaders, constants, state).
pub struct Pipelines {
    ctx: Arc<Context>,
    made: Memo<Key, Arc<Pipeline>>,
}

impl Pipelines {
    pub fn new(ctx: &Arc<Context>) -> Self {
        Self {
            ctx: ctx.clone(),
            made: Memo::new(),
        }
    }

    /// The device the pipelines are built on.
    pub fn ctx(&self) -> &Arc<Context> {
        &self.ctx
    }

    /// `Pipeline::compute_specialized(shader, constants)`, once.
    pub fn compute(&self, shader: &str, constants: &[u32]) -> Result<Arc<Pipeline>> {
        let key = Key::Compute(shader.into(), constants.to_vec());
        self.made.get_or_try(key, || {
            Pipeline::compute_specialized(&self.ctx, shader, constants)
        })
    }

    /// `Pipeline::graphics(desc)`, once.
    pub fn graphics(&self, desc: &GraphicsDesc) -> Result<Arc<Pipeline>> {
        let key = Key::Graphics(format!("{desc:?}"));
        self.made
            .get_or_try(key, || Pipeline::graphics(&self.ctx, desc))
    }

    /// How many pipelines it has built.
    pub fn len(&self) -> usize {
        self.made.len()
    }

    /// Each pipeline's name and creation time (creation feedback), slowest
    /// first; those the driver gave no time for are left out.
    pub fn creation_times(&self) -> Vec<(String, f64)> {
        let mut out: Vec<(String, f64)> = self
            .made
            .values()
            .iter()
            .filter_map(|p| Some((p.name.clone(), p.creation_ns?)))
            .collect();
        out.sort_by(|a, b| b.1.total_cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
        out
    }

    pub fn is_empty(&self) -> bool {
        self.made.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::Memo;
    use std::cell::Cell;

    #[test]
    fn a_value_is_made_once_per_key_and_a_failure_is_not_kept() {
        let memo: Memo<(&str, Vec<u32>), usize> = Memo::new();
        let made = Cell::new(0);
        let make = || -> Result<usize, String> {
            made.set(made.get() + 1);
            Ok(made.get())
        };
        assert_eq!(memo.get_or_try(("blur.comp", vec![7]), make), Ok(1));
        assert_eq!(
            memo.get_or_try(("blur.comp", vec![7]), make),
            Ok(1),
            "cached"
        );
        assert_eq!(
            memo.get_or_try(("blur.comp", vec![0]), make),
            Ok(2),
            "other constants"
        );
        assert_eq!(memo.get_or_try(("sh_reduce.comp", vec![]), make), Ok(3));
        assert_eq!((made.get(), memo.len()), (3, 3));
        let failed = memo.get_or_try(("bad.comp", vec![]), || Err::<usize, _>("no".to_string()));
        assert!(failed.is_err());
        assert_eq!(
            memo.get_or_try(("bad.comp", vec![]), make),
            Ok(4),
            "tried again"
        );
    }
}
