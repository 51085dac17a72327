//! A glTF writer for tests: one binary buffer in a data URI, its views and accessors.

use super::base64;
use serde_json::{json, Value};

/// Accumulates one binary buffer, its bufferViews and accessors.
#[derive(Default)]
pub struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    pub fn view(&mut self, bytes: &[u8]) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    pub fn acc(&mut self, bytes: &[u8], component: u32, count: usize, ty: &str, normalized: bool) -> usize {
        let view = self.view(bytes);
        let mut a = json!({"bufferView": view, "componentType": component, "count": count, "type": ty});
        if normalized {
            a["normalized"] = json!(true);
        }
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    /// An accessor written out by the test (a sparse one, say); its views come from [`Builder::view`].
    pub fn raw_accessor(&mut self, a: Value) -> usize {
        self.accessors.push(a);
        self.accessors.len() - 1
    }

    pub fn f32s(&mut self, values: &[f32], count: usize, ty: &str) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.acc(&bytes, 5126, count, ty, false)
    }

    /// A VEC3 float accessor with the `min`/`max` glTF requires of POSITION.
    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let a = self.f32s(p.as_flattened(), p.len(), "VEC3");
        let lo: Vec<f32> = (0..3).map(|i| p.iter().map(|v| v[i]).fold(f32::INFINITY, f32::min)).collect();
        let hi: Vec<f32> = (0..3).map(|i| p.iter().map(|v| v[i]).fold(f32::NEG_INFINITY, f32::max)).collect();
        self.accessors[a]["min"] = json!(lo);
        self.accessors[a]["max"] = json!(hi);
        a
    }

    /// The finished `.gltf` bytes: `doc` plus the buffer, views and accessors.
    pub fn finish(self, mut doc: Value) -> Vec<u8> {
        let uri = format!("data:application/octet-stream;base64,{}", base64(&self.bin));
        doc["asset"] = json!({"version": "2.0"});
        doc["buffers"] = json!([{"byteLength": self.bin.len(), "uri": uri}]);
        doc["bufferViews"] = Value::Array(self.views);
        doc["accessors"] = Value::Array(self.accessors);
        serde_json::to_vec(&doc).unwrap()
    }
}
