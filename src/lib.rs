#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub use platen_ident as ident;
pub use platen_integrate as integrate;
pub use platen_io as io;
pub use platen_model as model;
pub use platen_scenario as scenario;
pub use platen_signal as signal;
