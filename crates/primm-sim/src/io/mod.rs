//! Recorded measurement sequences and their CSV file format.
//!
//! [`Sequence`] and [`RecordedFrame`] are what the scenario generator produces and what the CSV
//! reader returns; [`RecordedFrame::to_frame`] turns a recorded frame into the tracker's
//! [`Frame`](primm_core::measurement::Frame).

pub mod association_csv;
pub mod measurement_csv;
mod recording;
pub mod track_csv;

pub use measurement_csv::{
    dataset_files, read_dataset_dir, read_sequence, read_sequence_file, write_sequence, write_sequence_file,
    CsvError, CsvErrorKind,
};
pub use recording::{
    EgoPose, MeasurementOrigin, RecordedFrame, RecordedMeasurement, Sequence, TooManyMeasurements,
};
