//! The layout of the TOML file: the tracker's sections as `primm-core` defines them, except
//! that the `predictor` section also holds the inference keys ([`InferenceConfig`]). The file
//! is read straight from its text, so that an error points at its line.
//!
//! Both conversions name every field: a section or predictor key added to the core without
//! being added here fails to compile.

use crate::{InferenceConfig, InferenceEngine, Settings};
use primm_core::config::{
    AssociationConfig, ClassTable, Config, CoordinatesConfig, ImmConfig, LearnedProcessNoise,
    PredictorConfig, TrackerConfig,
};
use primm_core::measurement::ClassSet;
use serde::{Deserialize, Serialize};

/// The whole file.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct FileLayout {
    imm: ImmConfig,
    association: AssociationConfig,
    tracker: TrackerConfig,
    classes: ClassTable,
    #[serde(default)]
    predictor: PredictorSection,
    #[serde(default)]
    frame: CoordinatesConfig,
}

/// The `predictor` section: the tracker's keys, then the inference keys.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct PredictorSection {
    deadline_ms: f64,
    max_displacement_speed_mps: f64,
    process_noise: LearnedProcessNoise,
    learned_process_noise_scale: f64,
    inference_threads: usize,
    engine: InferenceEngine,
    classes: ClassSet,
}

impl Default for PredictorSection {
    fn default() -> Self {
        Self::from_parts(&PredictorConfig::default(), &InferenceConfig::default())
    }
}

impl PredictorSection {
    fn from_parts(predictor: &PredictorConfig, inference: &InferenceConfig) -> Self {
        let PredictorConfig {
            max_displacement_speed_mps,
            process_noise,
            learned_process_noise_scale,
            classes,
        } = predictor.clone();
        let InferenceConfig { deadline_ms, inference_threads, engine } = *inference;
        Self {
            deadline_ms,
            max_displacement_speed_mps,
            process_noise,
            learned_process_noise_scale,
            inference_threads,
            engine,
            classes,
        }
    }
}

impl From<FileLayout> for Settings {
    fn from(file: FileLayout) -> Self {
        let FileLayout { imm, association, tracker, classes, predictor, frame } = file;
        let PredictorSection {
            deadline_ms,
            max_displacement_speed_mps,
            process_noise,
            learned_process_noise_scale,
            inference_threads,
            engine,
            classes: predicted_classes,
        } = predictor;
        Settings {
            tracker: Config {
                imm,
                association,
                tracker,
                classes,
                predictor: PredictorConfig {
                    max_displacement_speed_mps,
                    process_noise,
                    learned_process_noise_scale,
                    classes: predicted_classes,
                },
                frame,
            },
            inference: InferenceConfig { deadline_ms, inference_threads, engine },
        }
    }
}

impl From<&Settings> for FileLayout {
    fn from(settings: &Settings) -> Self {
        let Config { imm, association, tracker, classes, predictor, frame } = settings.tracker.clone();
        FileLayout {
            imm,
            association,
            tracker,
            classes,
            predictor: PredictorSection::from_parts(&predictor, &settings.inference),
            frame,
        }
    }
}
