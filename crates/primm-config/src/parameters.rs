//! `docs/parameters.md`: every key of the configuration file with its type, unit, default,
//! valid range and what it does.
//!
//! The keys, types and defaults come from the code (the serialised [`Settings::default`], which
//! a test holds equal to `config/primm.toml`), the units from the keys' names; the ranges and
//! descriptions are [`PARAMETERS`] below. A test checks that every key of the configuration is
//! described here and nothing else, and that the committed `docs/parameters.md` is what
//! [`parameters_markdown`] writes (`PRIMM_WRITE_PARAMETERS=1 cargo test -p primm-config
//! parameters` rewrites it; `primm config parameters` prints it).

use crate::file::FileLayout;
use crate::Settings;
use std::collections::BTreeMap;
use toml::Value;

/// One key's description: where it lies (`classes.<class>` stands for every class,
/// `frame.sensors[]` for every sensor), its valid values and what it does.
struct Parameter {
    key: &'static str,
    range: &'static str,
    what: &'static str,
}

/// Shorthand for the table below.
const fn p(key: &'static str, range: &'static str, what: &'static str) -> Parameter {
    Parameter { key, range, what }
}

/// Every key, section by section, in the order of `config/primm.toml`.
#[rustfmt::skip]
const PARAMETERS: &[Parameter] = &[
    p("imm.modes", "non-empty subset of pr, cv, ca, ct", "Active modes (the commands' --method overrides it)."),
    p("imm.transition", "rows of probabilities summing to 1", "Mode-transition matrix π[i][j] = P(mode j given mode i), order pr, cv, ca, ct."),
    p("imm.initial_mode_probabilities", "probabilities, some mass on the active modes", "Mode probabilities of a new track (renormalised over the active modes)."),
    p("imm.likelihood_temperature", "> 0", "Exponent τ on the mode likelihoods in the mode-probability update."),
    p("imm.mode_probability_floor", "[0, 1 / active modes)", "No active mode's probability falls below this."),
    p("association.velocity_weight_s", ">= 0", "λ_v: weight of the radial-velocity difference in the paper cost."),
    p("association.velocity_cap_mps", ">= 0", "v_max: cap on the radial-velocity difference in the paper cost."),
    p("association.cost", "paper, likelihood", "Cost pairing tracks with measurements: the paper's distance or the negative log-likelihood."),
    p("association.stages", "joint, confirmed_first", "One assignment over all tracks, or confirmed tracks before tentative ones."),
    p("association.likelihood_gate_chi2", "> 0", "Gate of the likelihood cost on the squared Mahalanobis distance (χ², 3 degrees of freedom)."),
    p("association.likelihood_gate_distance_m", "> 0", "Second gate of the likelihood cost: largest distance of a measurement from a track's predicted centre beyond its extent's largest reflection offset, m (inf: none)."),
    p("tracker.max_frame_interval_s", "> 0", "Frames further apart than this are rejected."),
    p("tracker.confirmation_hits", ">= 1", "Counts lifecycle: hits that confirm a tentative track."),
    p("tracker.tentative_max_misses", ">= 0", "Counts lifecycle: consecutive misses that delete a tentative track."),
    p("tracker.tentative_max_coast_s", "> 0", "A tentative track coasting longer than this is deleted."),
    p("tracker.confirmed_max_misses", ">= 0", "Counts lifecycle: consecutive misses that delete a confirmed track."),
    p("tracker.max_coast_s", "> 0", "A track coasting longer than this is deleted."),
    p("tracker.lifecycle", "counts, existence", "Whether hit/miss counts or the existence probability confirm and delete tracks."),
    p("tracker.initial_existence_probability", "(0, 1)", "Existence probability of a track started by one measurement."),
    p("tracker.confirmation_existence_probability", "(0, 1)", "Existence lifecycle: the probability that confirms a tentative track."),
    p("tracker.deletion_existence_probability", "[0, confirmation_existence_probability)", "Existence lifecycle: a track below this probability is deleted."),
    p("tracker.existence_persistence_time_s", "> 0", "Mean time an object goes on existing: existence decays by exp(-dt / T) per frame."),
    p("tracker.duplicate_updates", ">= 0 (0: off)", "Exclusive updates of one of two overlapping tracks after which the younger is merged into the older."),
    p("tracker.max_frame_delay_s", "[0, max_frame_interval_s] (0: off)", "A frame up to this much older than the newest is tracked in its place."),
    p("tracker.replay_frames", "0 to 64 (0: off)", "Recent frames kept for tracking a late frame in its place."),
    p("tracker.max_ego_speed_mps", "> 0", "Faster ego motion between two poses is an odometry reset."),
    p("tracker.max_ego_yaw_rate_radps", "> 0", "Faster ego turning between two poses is an odometry reset."),
    p("predictor.deadline_ms", "(0, 1000]", "Service and threaded C API: longest wait for a frame's learned displacements."),
    p("predictor.max_displacement_speed_mps", "> 0", "A learned displacement implying a faster motion is rejected and counted."),
    p("predictor.process_noise", "learned, constant", "Q_PR of the PR mode: the model's own covariance (scaled) or the constant of `classes.<class>.learned`."),
    p("predictor.learned_process_noise_scale", "> 0", "Factor on the model's covariance with process_noise = learned."),
    p("predictor.inference_threads", "1 to 8", "Service and threaded C API: inference threads sharing each frame's batch."),
    p("predictor.engine", "native, tract", "What runs the PR model: primm's own forward pass (shipped architecture) or tract."),
    p("predictor.classes", "subset of car, pedestrian, two_wheeler", "PR-IMM: the classes whose tracks the learned model predicts."),
    p("frame.tracking_frame", "world, vehicle", "Frame the tracks are kept in when frames carry an ego pose."),
    p("frame.sensors", "at most 16 sensors, unique ids", "Mounting pose and properties of each radar, by sensor id (a file that sets it replaces the whole list)."),
    p("frame.unknown_sensor_margin_rad", "[0, π]", "A radar without a mount looks where its detections lie, widened by this on each side."),
    p("frame.unknown_sensor_margin_m", ">= 0", "... out to the farthest detection plus this."),
    p("frame.unmounted_reflection", "outline, centre, auto", "Where the detections of radars without a mount lie on an extended object."),
    p("frame.estimation.reflection_prior_samples", "(0, 1e9]", "Weight of the configured offset scale in the sensors' reflection estimates."),
    p("frame.estimation.reflection_window_samples", "(0, 1e9]", "Memory of the reflection estimates."),
    p("frame.estimation.detection_prior_samples", "(0, 1e9]", "Weight of the configured detection probability in the detection estimates."),
    p("frame.estimation.clutter_prior_scans", "(0, 1e9]", "Weight of the configured clutter density in the clutter estimates."),
    p("frame.estimation.existence_window_samples", "(0, 1e9]", "Memory of the detection and clutter estimates."),
    p("frame.platform", "moving, stationary, auto", "Whether the sensors move: frames without an ego pose in the vehicle frame, in the world frame at the origin, or as their radial velocities say."),
    p("frame.unmounted_detections", "points, objects, auto", "What one detection of a radar without a mount is: a point of a point cloud (grouped), an object, or decided from the data."),
    p("frame.grouping.link_distance_m", "[0, 20]", "Point clouds: largest distance between two linked detections at zero range."),
    p("frame.grouping.link_distance_per_range", "[0, 1]", "Growth of the link distance with range, m per m."),
    p("frame.grouping.link_radial_velocity_gap_mps", "[0, 100]", "Largest difference of radial velocity between two linked detections."),
    p("frame.grouping.pedestrian_link_scale", "(0, 1]", "Share of the link distance within which two detections both labelled pedestrian link."),
    p("frame.grouping.owner_margin_m", "[0, 20]", "Point clouds: how far beyond a confirmed track's box a detection still joins its group (when its radial velocity is one of the object's returns)."),
    p("frame.grouping.points_share_threshold", "(0, 1)", "detections = auto: share of confirmed vehicle-track scans with several detections above which a radar delivers points."),
    p("frame.grouping.points_fallback_share", "[0, points_share_threshold)", "detections = auto: share below which a radar that delivers points falls back to objects."),
    p("frame.grouping.points_prior_scans", "(0, 1e9]", "Weight of the prior share 0 (objects), in track scans."),
    p("frame.grouping.points_window_scans", "(0, 1e9]", "Memory of the share, in track scans."),
    p("frame.grouping.detection_probability_factor", "(0, 1000]", "Factor on the detection probability of a radar that missed a track while it groups its detections (a group misses its object only when all its detections do)."),
    p("frame.grouping.group_noise_scale", "(0, 1]", "Factor on the radar's noise and the contour's spread over the count in the noise of a group moved to its object's centre (1: the mean of independent points)."),
    p("frame.grouping.points_evidence_margin_m", "[0, 20] m", "How far beyond a confirmed vehicle track's box a detection still counts towards an auto radar's share of multiples, m."),
    p("frame.grouping.points_scan_share", "(0, 1]", "Before its first track scan, an auto radar starts as points when more than this share of the auto radars' vehicle detections so far lie in clusters of three or more linked ones (1: never)."),
    p("frame.grouping.points_scan_prior_detections", "[0, 1e9]", "Weight of the share 0 (no clusters) in that share, in vehicle detections."),
    p("frame.grouping.points_pool_scans", "[0, 1e9]", "Weight of the share pooled over the auto radars with at least this many track scans in each radar's decision, in track scans (0: each radar alone)."),
    p("frame.sensors[].id", "0 to 65535", "The sensor id that measurements carry."),
    p("frame.sensors[].x_m", "finite, within 100 m", "Position from the reference point (centre of the rear axle), forward."),
    p("frame.sensors[].y_m", "finite, within 100 m", "Position from the reference point, to the left."),
    p("frame.sensors[].yaw_rad", "finite", "Boresight yaw."),
    p("frame.sensors[].half_fov_rad", "(0, π]", "Half opening angle of the field of view."),
    p("frame.sensors[].max_range_m", "> 0", "Range of the field of view."),
    p("frame.sensors[].detection_probability_factor", "> 0", "Factor on every class's detection probability for this sensor."),
    p("frame.sensors[].clutter_density_factor", ">= 0", "Factor on every class's clutter density for this sensor."),
    p("frame.sensors[].range_std_m", ">= 0", "The radar's own range noise (world-frame steps; 0: the class's R alone)."),
    p("frame.sensors[].azimuth_std_rad", "[0, 0.5]", "The radar's own azimuth noise at boresight (world-frame steps)."),
    p("frame.sensors[].azimuth_std_max_factor", "[1, 10]", "Growth of the azimuth noise as 1/cos off boresight, up to this factor."),
    p("frame.sensors[].reflection", "outline, centre, auto", "Where the sensor's detections of an extended object lie: outline (offset_scale), centre, or estimated."),
    p("frame.sensors[].detections", "points, objects, auto", "What one of the sensor's detections is: a point of a point cloud (grouped into objects), an object, or decided from the data."),
    p("classes.<class>.paper_gate_m", "> 0", "Gate of the paper association cost (unused by the likelihood cost)."),
    p("classes.<class>.measurement_noise_covariance_m2", "symmetric positive definite", "R of the CV, CA and CT modes: where on the object the reflection lies."),
    p("classes.<class>.initial_radial_speed_std_mps", "> 0", "Spread of a new track's velocity along the line of sight."),
    p("classes.<class>.initial_tangential_speed_std_mps", "> 0", "Spread of a new track's velocity across the line of sight."),
    p("classes.<class>.max_speed_mps", "> 0", "Highest speed over ground of the class; faster estimates are scaled back (world frame)."),
    p("classes.<class>.likelihood_radial_velocity_std_mps", "> 0", "Likelihood cost: spread of a radial velocity minus the track's last one."),
    p("classes.<class>.duplicate_distance_m", "> 0", "Duplicate check: largest distance between two tracks of one object."),
    p("classes.<class>.duplicate_speed_difference_mps", "> 0", "Duplicate check: largest velocity difference between two tracks of one object (also between two tracks of a class with an extent whose boxes overlap, in a point cloud's owner look-up)."),
    p("classes.<class>.existence.detection_probability", "(0, 1)", "Probability that a sensor with the object in view reports it in a scan."),
    p("classes.<class>.existence.clutter_density_per_m2", ">= 0", "False detections of the class per scan and square metre of field of view."),
    p("classes.<class>.radial_velocity_update.enabled", "true, false", "Whether the radial velocity updates the velocity (a Kalman row of CV, CA, CT)."),
    p("classes.<class>.radial_velocity_update.std_mps", "> 0", "Noise of that row: the radial velocity as a measurement of the velocity."),
    p("classes.<class>.radial_velocity_update.gate_std", "> 0", "A row residual beyond this many standard deviations is left out (counted)."),
    p("classes.<class>.radial_velocity_update.line_of_sight", "predicted, reflection, measured", "Direction of the row: to the track's centre, to the expected reflection, or to the detection."),
    p("classes.<class>.extent.enabled", "true, false", "Track the class as an extended object (state: its centre)."),
    p("classes.<class>.extent.length_m", "> 0, at most 50", "Length of the object's box."),
    p("classes.<class>.extent.width_m", "> 0, at most length_m", "Width of the object's box."),
    p("classes.<class>.extent.contour_std_m", "> 0", "Spread of the reflection along the outline."),
    p("classes.<class>.extent.min_heading_speed_mps", "> 0", "Below this speed the box has no heading and is a disc."),
    p("classes.<class>.extent.offset_scale", "(0, 1]", "Where a detection lies between the centre (0) and the nearest point of the outline (1)."),
    p("classes.<class>.extent.absorb_extra_detections", "true, false", "An unassigned detection on a confirmed track's box starts no track (counted)."),
    p("classes.<class>.extent.absorb_margin_m", "[0, 10]", "Margin around the box for absorbing detections."),
    p("classes.<class>.constant_velocity.acceleration_psd_m2_per_s3", "> 0", "CV: spectral density of the white-noise acceleration."),
    p("classes.<class>.constant_acceleration.jerk_psd_m2_per_s5", "> 0", "CA: spectral density of the white-noise jerk."),
    p("classes.<class>.constant_acceleration.initial_acceleration_std_mps2", "> 0", "CA: spread of a new track's acceleration."),
    p("classes.<class>.coordinated_turn.acceleration_psd_m2_per_s3", "> 0", "CT: spectral density of the white-noise acceleration."),
    p("classes.<class>.coordinated_turn.turn_rate_psd_rad2_per_s3", "> 0", "CT: spectral density of the turn-rate random walk."),
    p("classes.<class>.coordinated_turn.initial_turn_rate_std_radps", "> 0", "CT: spread of a new track's turn rate."),
    p("classes.<class>.coordinated_turn.max_turn_rate_radps", "> 0", "CT: larger turn-rate estimates are clamped to this before predicting."),
    p("classes.<class>.learned.process_noise_covariance_m2", "symmetric positive definite", "Q_PR added to the PR covariance at every prediction (process_noise = constant)."),
    p("classes.<class>.learned.measurement_noise_covariance_m2", "symmetric positive definite", "R_PR, the measurement noise of the PR mode."),
    p("classes.<class>.imm.transition", "as imm.transition", "This class's transition matrix (absent: imm.transition)."),
    p("classes.<class>.imm.initial_mode_probabilities", "as imm.initial_mode_probabilities", "This class's initial mode probabilities (absent: the imm section's)."),
    p("classes.<class>.imm.compensated_transition", "as imm.transition", "The class's transition matrix in world-frame steps with an ego pose (absent: its transition)."),
    p("classes.<class>.imm.compensated_initial_mode_probabilities", "as imm.initial_mode_probabilities", "Initial mode probabilities of tracks started in such steps (absent: its initial_mode_probabilities)."),
];

/// Units by the end of a key's name, longest first.
const UNITS: &[(&str, &str)] = &[
    ("_rad2_per_s3", "rad²/s³"),
    ("_m2_per_s3", "m²/s³"),
    ("_m2_per_s5", "m²/s⁵"),
    ("_per_m2", "1/m²"),
    ("_radps", "rad/s"),
    ("_mps2", "m/s²"),
    ("_chi2", "χ²"),
    ("_mps", "m/s"),
    ("_rad", "rad"),
    ("_m2", "m²"),
    ("_ms", "ms"),
    ("_std", "standard deviations"),
    ("_hits", "count"),
    ("_misses", "count"),
    ("_frames", "count"),
    ("_updates", "count"),
    ("_threads", "count"),
    ("_m", "m"),
    ("_s", "s"),
];

/// The unit of `key`, from its name.
fn unit(key: &str) -> &'static str {
    UNITS.iter().find(|(suffix, _)| key.ends_with(suffix)).map_or("—", |(_, unit)| unit)
}

/// Every key of the default configuration, with its default values: one per class or sensor
/// where a key repeats for each (`None` where a class or sensor leaves it out).
fn default_keys() -> BTreeMap<String, Vec<(String, Value)>> {
    let file = FileLayout::from(&Settings::default());
    let table = toml::Table::try_from(&file).expect("the default configuration serialises");
    let mut keys = BTreeMap::new();
    collect(&table, "", "", &mut keys);
    keys
}

/// Adds the keys of `table` under `prefix` to `keys`; `instance` names the class or sensor.
fn collect(
    table: &toml::Table,
    prefix: &str,
    instance: &str,
    keys: &mut BTreeMap<String, Vec<(String, Value)>>,
) {
    for (name, value) in table {
        let path = if prefix.is_empty() { name.clone() } else { format!("{prefix}.{name}") };
        match value {
            Value::Table(inner) if path == "classes" => {
                for (class, section) in inner {
                    if let Value::Table(section) = section {
                        collect(section, "classes.<class>", class, keys);
                    }
                }
            }
            Value::Table(inner) => collect(inner, &path, instance, keys),
            Value::Array(items) if items.iter().all(Value::is_table) && !items.is_empty() => {
                keys.entry(path.clone()).or_default().push((instance.to_string(), value.clone()));
                for (index, item) in items.iter().enumerate() {
                    if let Value::Table(item) = item {
                        collect(item, &format!("{path}[]"), &format!("sensor {}", index + 1), keys);
                    }
                }
            }
            _ => keys.entry(path).or_default().push((instance.to_string(), value.clone())),
        }
    }
}

/// The type of a TOML value, in words.
fn type_name(value: &Value) -> String {
    match value {
        Value::String(_) => "string".into(),
        Value::Integer(_) => "integer".into(),
        Value::Float(_) => "float".into(),
        Value::Boolean(_) => "bool".into(),
        Value::Datetime(_) => "datetime".into(),
        Value::Table(_) => "table".into(),
        Value::Array(items) => match items.first() {
            Some(Value::Array(row)) => format!("{}×{} floats", items.len(), row.len()),
            Some(Value::Table(_)) => "array of tables".into(),
            Some(Value::String(_)) => "list of strings".into(),
            Some(_) => format!("{} floats", items.len()),
            None => "list".into(),
        },
    }
}

/// A default value as written in the table: the TOML value, or where to find a long one.
fn shown(value: &Value) -> String {
    match value {
        Value::Array(items) if items.iter().any(Value::is_table) => "see `config/primm.toml`".into(),
        Value::Array(rows) if rows.len() > 2 && rows.iter().all(Value::is_array) => {
            format!("{}×{} matrix, see `config/primm.toml`", rows.len(), rows.len())
        }
        _ => format!("`{value}`"),
    }
}

/// The default column: one value, or the value of each class or sensor.
fn defaults_cell(values: &[(String, Value)], key: &str) -> String {
    let classes = ["car", "pedestrian", "two_wheeler"];
    let first = &values[0].1;
    let every_class_has_it = !key.starts_with("classes.") || values.len() == classes.len();
    if every_class_has_it && values.iter().all(|(_, value)| value == first) {
        return shown(first);
    }
    let mut parts: Vec<String> =
        values.iter().map(|(instance, value)| format!("{instance}: {}", shown(value))).collect();
    if key.starts_with("classes.") {
        for class in classes.iter().filter(|class| values.iter().all(|(instance, _)| instance != *class)) {
            parts.push(format!("{class}: absent"));
        }
    }
    parts.join("; ")
}

/// `docs/parameters.md`.
pub fn parameters_markdown() -> String {
    let keys = default_keys();
    let mut out = String::from(
        "# Configuration parameters\n\n\
         Every key of primm's configuration file, generated from the code by `primm config \
         parameters` (a test keeps this file current). A configuration file is laid over \
         `config/primm.toml` key by key: it sets only what it changes, and every other key keeps \
         the default below. `primm config show --config FILE --diff` prints what a file changes. \
         Units are part of the key names; `classes.<class>` stands for `classes.car`, \
         `classes.pedestrian` and `classes.two_wheeler`, `frame.sensors[]` for each \
         `[[frame.sensors]]` entry. Validation refuses a value out of its range with the key's \
         name; an unknown key, or a value of the wrong type, with its line in the file.\n",
    );
    let mut section = "";
    for parameter in PARAMETERS {
        let this_section = section_of(parameter.key);
        if this_section != section {
            section = this_section;
            out.push_str(&format!(
                "\n## `{section}`\n\n| key | type | unit | default | valid values | what it does |\n|---|---|---|---|---|---|\n"
            ));
        }
        let values = keys.get(parameter.key).map(Vec::as_slice).unwrap_or_default();
        let (kind, default) = match values.first() {
            Some((_, value)) => (type_name(value), defaults_cell(values, parameter.key)),
            None => ("—".into(), "absent".into()),
        };
        let name = &parameter.key[section.len() + 1..];
        out.push_str(&format!(
            "| `{name}` | {kind} | {} | {default} | {} | {} |\n",
            unit(parameter.key),
            parameter.range,
            parameter.what
        ));
    }
    out
}

/// The section a key is listed under: everything before its last dot.
fn section_of(key: &str) -> &str {
    key.rfind('.').map_or(key, |dot| &key[..dot])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_of_the_configuration_is_described_and_nothing_else() {
        let keys: Vec<String> = default_keys().into_keys().collect();
        let mut described: Vec<String> =
            PARAMETERS.iter().map(|parameter| parameter.key.to_string()).collect();
        described.sort();
        let missing: Vec<&String> = keys.iter().filter(|key| !described.contains(key)).collect();
        let unknown: Vec<&String> = described.iter().filter(|key| !keys.contains(key)).collect();
        assert!(missing.is_empty(), "keys without a description in PARAMETERS: {missing:?}");
        assert!(unknown.is_empty(), "descriptions of keys the configuration does not have: {unknown:?}");
        let mut unique = described.clone();
        unique.dedup();
        assert_eq!(unique, described, "a key is described twice");
    }

    #[test]
    fn the_committed_parameters_page_is_what_the_code_generates() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/parameters.md");
        let generated = parameters_markdown();
        if std::env::var_os("PRIMM_WRITE_PARAMETERS").is_some() {
            std::fs::write(path, &generated).expect("docs/parameters.md is writable");
        }
        let committed = std::fs::read_to_string(path).unwrap_or_default();
        assert!(
            committed == generated,
            "stale docs/parameters.md: run `PRIMM_WRITE_PARAMETERS=1 cargo test -p primm-config parameters`"
        );
    }

    #[test]
    fn units_follow_the_key_names() {
        assert_eq!(unit("classes.<class>.paper_gate_m"), "m");
        assert_eq!(unit("tracker.max_coast_s"), "s");
        assert_eq!(unit("classes.<class>.coordinated_turn.turn_rate_psd_rad2_per_s3"), "rad²/s³");
        assert_eq!(unit("classes.<class>.existence.clutter_density_per_m2"), "1/m²");
        assert_eq!(unit("tracker.lifecycle"), "—");
    }
}
