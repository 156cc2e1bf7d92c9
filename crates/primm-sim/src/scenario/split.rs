//! Data set splits and their Table I style summary.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::events::{count_events, EventCounts};
use super::GeneratedSequence;
use crate::io::Sequence;
use primm_core::measurement::ObjectClass;

/// A data set split.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Split {
    /// Training sequences (PR model training).
    Train,
    /// Validation sequences (model selection).
    Validation,
    /// Evaluation sequences (tracker evaluation).
    Evaluation,
}

impl Split {
    /// All splits in the order of the paper's Table I.
    pub const ALL: [Split; 3] = [Split::Train, Split::Validation, Split::Evaluation];

    /// Lower-case name (`train`, `validation`, `evaluation`), also the directory name.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Validation => "validation",
            Split::Evaluation => "evaluation",
        }
    }

    /// The split called `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

impl std::fmt::Display for Split {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Counts of one split in the layout of the paper's Table I (`tab:dataset`), plus the number of
/// frames with hard association situations when ground truth is available.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SplitSummary {
    /// The split.
    pub split: Split,
    /// Number of sequences.
    pub sequences: usize,
    /// Number of frames (radar scans).
    pub frames: usize,
    /// Number of car measurements (object frames).
    pub car_object_frames: usize,
    /// Number of pedestrian measurements (object frames).
    pub pedestrian_object_frames: usize,
    /// Close-proximity and crossing frames, summed over the generated sequences added.
    pub events: Option<EventCounts>,
}

impl SplitSummary {
    /// An empty summary of `split`.
    pub fn new(split: Split) -> Self {
        Self {
            split,
            sequences: 0,
            frames: 0,
            car_object_frames: 0,
            pedestrian_object_frames: 0,
            events: None,
        }
    }

    /// Adds a recorded sequence (no ground truth: event counts unchanged).
    pub fn add_recorded(&mut self, sequence: &Sequence) {
        self.sequences += 1;
        self.frames += sequence.frames.len();
        self.car_object_frames += sequence.class_count(ObjectClass::Car);
        self.pedestrian_object_frames += sequence.class_count(ObjectClass::Pedestrian);
    }

    /// Adds a generated sequence, including its event counts.
    pub fn add_generated(&mut self, generated: &GeneratedSequence) {
        self.add_recorded(&generated.sequence);
        *self.events.get_or_insert_with(EventCounts::default) += count_events(generated);
    }

    /// Total number of object measurements.
    pub fn object_frames(&self) -> usize {
        self.car_object_frames + self.pedestrian_object_frames
    }
}

fn thousands(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Formats summaries as a plain-text table with the columns of the paper's Table I, followed by
/// the close-proximity and crossing frame counts where known.
pub fn format_table(summaries: &[SplitSummary]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<12} {:>10} {:>10} {:>18} {:>25} {:>16} {:>16}",
        "Split",
        "Sequences",
        "Frames",
        "Car object frames",
        "Pedestrian object frames",
        "Close proximity",
        "Crossing"
    );
    for s in summaries {
        let (close, crossing) = match s.events {
            Some(e) => (thousands(e.close_proximity_frames), thousands(e.crossing_frames)),
            None => ("-".to_owned(), "-".to_owned()),
        };
        let mut name = s.split.name().to_owned();
        name[..1].make_ascii_uppercase();
        let _ = writeln!(
            out,
            "{:<12} {:>10} {:>10} {:>18} {:>25} {:>16} {:>16}",
            name,
            thousands(s.sequences),
            thousands(s.frames),
            thousands(s.car_object_frames),
            thousands(s.pedestrian_object_frames),
            close,
            crossing
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thousands_separators() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(999), "999");
        assert_eq!(thousands(1000), "1,000");
        assert_eq!(thousands(32555), "32,555");
        assert_eq!(thousands(1234567), "1,234,567");
    }

    #[test]
    fn split_names_round_trip() {
        for split in Split::ALL {
            assert_eq!(Split::from_name(split.name()), Some(split));
        }
        assert_eq!(Split::from_name("test"), None);
    }
}
