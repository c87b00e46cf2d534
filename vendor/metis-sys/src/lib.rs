//! Raw FFI to the vendored METIS 5.2.1 (metis-sys 0.3.2's bindings, unchanged); see PATCHES.md
//! for what differs from metis-sys.
#![allow(non_upper_case_globals)]
#![allow(non_camel_case_types)]
#![allow(non_snake_case)]

include!("../gen/bindings.rs");
