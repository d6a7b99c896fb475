//! Result cache: one JSON-lines file per sweep in the output folder, each line
//! `{"key": <16 hex digits>, "value": <result>}`. The key is an FNV-1a 64-bit hash (stable
//! across Rust versions, unlike `DefaultHasher`) of a text describing every input of the
//! job (plant airframe, controller and its parameters, job parameters, [`CODE_VERSION`]).
//! A re-run only computes jobs whose key is not in the file; lines are appended as jobs
//! finish, so an interrupted sweep resumes where it stopped.

use serde::{de::DeserializeOwned, Serialize};
use std::collections::HashMap;
use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Version of the code behind the results: a hash (by `build.rs`) of the sources of the
/// physics, mission, closed-loop, controller and analysis crates. Any edit there
/// invalidates every cached result.
pub const CODE_VERSION: &str = env!("RESULTS_SOURCE_HASH");

/// FNV-1a 64-bit hash of `text`.
pub fn fnv1a64(text: &str) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.as_bytes() {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Cache key of a job description (hex of [`fnv1a64`] of `CODE_VERSION | description`).
pub fn key(description: &str) -> String {
    format!("{:016x}", fnv1a64(&format!("{CODE_VERSION}|{description}")))
}

/// A JSON-lines cache file.
pub struct Cache {
    path: Option<PathBuf>,
    entries: HashMap<String, serde_json::Value>,
    writer: Mutex<Option<File>>,
    hits: std::sync::atomic::AtomicUsize,
}

impl Cache {
    /// Open (creating the folder) `dir/<name>.jsonl`; `dir = None` gives a memory-only cache.
    pub fn open(dir: Option<&Path>, name: &str) -> std::io::Result<Self> {
        let mut entries = HashMap::new();
        let Some(dir) = dir else {
            return Ok(Self {
                path: None,
                entries,
                writer: Mutex::new(None),
                hits: 0.into(),
            });
        };
        std::fs::create_dir_all(dir)?;
        let path = dir.join(format!("{name}.jsonl"));
        if path.exists() {
            for line in BufReader::new(File::open(&path)?).lines() {
                let line = line?;
                if let Ok(serde_json::Value::Object(mut m)) = serde_json::from_str::<serde_json::Value>(&line) {
                    if let (Some(serde_json::Value::String(k)), Some(v)) = (m.remove("key"), m.remove("value")) {
                        entries.insert(k, v);
                    }
                }
            }
        }
        let file = OpenOptions::new().create(true).append(true).open(&path)?;
        Ok(Self {
            path: Some(path),
            entries,
            writer: Mutex::new(Some(file)),
            hits: 0.into(),
        })
    }

    /// Path of the cache file, if on disk.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Number of entries loaded from disk.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing was loaded.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Number of [`Cache::get_or`] calls answered from the cache.
    pub fn hits(&self) -> usize {
        self.hits.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The cached value of `key`, or `compute()` (then appended to the file).
    pub fn get_or<T: Serialize + DeserializeOwned>(&self, key: &str, compute: impl FnOnce() -> T) -> T {
        if let Some(v) = self.entries.get(key) {
            if let Ok(t) = serde_json::from_value::<T>(v.clone()) {
                self.hits.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                return t;
            }
        }
        let t = compute();
        if let Ok(value) = serde_json::to_value(&t) {
            let line = serde_json::json!({ "key": key, "value": value }).to_string();
            if let Ok(mut guard) = self.writer.lock() {
                if let Some(f) = guard.as_mut() {
                    let _ = writeln!(f, "{line}");
                }
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv_known_values() {
        assert_eq!(fnv1a64(""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64("a"), 0xaf63_dc4c_8601_ec8c);
    }
}
