//! Everything a run writes: the output directory with atomic file writes, `summary.json`,
//! CSV tables and VTK files for ParaView.

pub mod csv_table;
pub mod dir;
pub mod summary;
pub mod vtk;

pub use csv_table::CsvTable;
pub use dir::OutputDir;
pub use summary::Summary;
