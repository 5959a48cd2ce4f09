//! Arbitrary bytes read as a LandXML mesh: an error naming the input or a valid
//! mesh, never a panic (see `tinsmith_fuzz::read_mesh`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use tinsmith_formats::MeshFormat;

fuzz_target!(|data: &[u8]| tinsmith_fuzz::read_mesh(data, MeshFormat::LandXml));
