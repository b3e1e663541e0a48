//! The FMI 2.0 co-simulation binary `PeriodicContact.so`: exactly the 34 FMI 2 CS functions,
//! thin wrappers over the generic FMI 2 shell (`periodic_contact::fmi::fmi2`) with the contact model.
//! Build: `cargo build --release` → `target/release/libPeriodicContact.so`.
#![allow(non_snake_case)]

periodic_contact::export_fmi2!(periodic_contact::fmu_model::ContactModel);
