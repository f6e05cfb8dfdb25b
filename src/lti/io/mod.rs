//! File formats of named real matrices, below the systems: JSON matrices
//! (`matrix_json.rs`: rows of numbers, shape and magnitude checks) and MATLAB level-5 MAT-files
//! (`mat_file.rs`, reading and writing; `mat_inflate.rs`, decompressing a compressed variable
//! within a size limit). Nothing here knows plants or controllers: `system/plant.rs` and
//! `system/controller.rs` turn these matrices into their own file forms.
//!
//! Imports nothing from the other parts of `lti` (the order is in docs/ARCHITECTURE.md §1).

pub(crate) mod mat_file;
pub(crate) mod mat_inflate;
pub(crate) mod matrix_json;
