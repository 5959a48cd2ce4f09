//! Welding: formats that store each triangle's corners by value (STL, GeoJSON, FlatGeobuf)
//! are read back into shared vertices by exact position.

use std::collections::HashMap;

/// Gives each distinct position (compared bit for bit) one vertex index, in order of first
/// appearance.
#[derive(Debug, Default)]
pub(crate) struct Welder {
    index: HashMap<[u64; 3], u32>,
    vertices: Vec<[f64; 3]>,
}

impl Welder {
    /// The index of `p`, adding it as a new vertex if it was not seen before; `None` when
    /// there are more vertices than `u32` indices.
    pub(crate) fn vertex(&mut self, p: [f64; 3]) -> Option<u32> {
        // +0.0 and -0.0 are the same position.
        let key = p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        if let Some(&i) = self.index.get(&key) {
            return Some(i);
        }
        let i = u32::try_from(self.vertices.len()).ok()?;
        self.index.insert(key, i);
        self.vertices.push(p);
        Some(i)
    }

    /// The distinct positions, in order of first appearance.
    pub(crate) fn into_vertices(self) -> Vec<[f64; 3]> {
        self.vertices
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_positions_share_an_index_in_first_seen_order() {
        let mut welder = Welder::default();
        let a = [1.0, 2.0, 3.0];
        let b = [1.0, 2.0, 3.000_000_000_000_000_4];
        assert_eq!(welder.vertex(a), Some(0));
        assert_eq!(welder.vertex(b), Some(1));
        assert_eq!(welder.vertex(a), Some(0));
        assert_eq!(welder.vertex([0.0, -0.0, 1.0]), Some(2));
        assert_eq!(welder.vertex([-0.0, 0.0, 1.0]), Some(2));
        assert_eq!(welder.into_vertices(), vec![a, b, [0.0, -0.0, 1.0]]);
    }
}
