#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub use platen_compare as compare;
pub use platen_ident as ident;
pub use platen_integrate as integrate;
pub use platen_model as model;
pub use platen_report as report;
pub use platen_scenario as scenario;
pub use platen_signal as signal;
