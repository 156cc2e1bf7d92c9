//! Class labels as data sets and perception stacks write them, read as primm's classes: the one
//! mapping that the measurement CSV reader, the C API and every other text input share.

use crate::measurement::ObjectClass;

/// The longest label compared, in bytes (longer ones name no class).
const MAX_LABEL_BYTES: usize = 32;

/// Every accepted label, normalised (lower case, `_` between words), with its class.
const LABELS: [(&str, ObjectClass); 18] = [
    ("car", ObjectClass::Car),
    ("vehicle", ObjectClass::Car),
    ("passenger_car", ObjectClass::Car),
    ("van", ObjectClass::Car),
    ("truck", ObjectClass::Car),
    ("bus", ObjectClass::Car),
    ("large_vehicle", ObjectClass::Car),
    ("trailer", ObjectClass::Car),
    ("pedestrian", ObjectClass::Pedestrian),
    ("person", ObjectClass::Pedestrian),
    ("pedestrian_group", ObjectClass::Pedestrian),
    ("two_wheeler", ObjectClass::TwoWheeler),
    ("bicycle", ObjectClass::TwoWheeler),
    ("bike", ObjectClass::TwoWheeler),
    ("cyclist", ObjectClass::TwoWheeler),
    ("motorcycle", ObjectClass::TwoWheeler),
    ("motorbike", ObjectClass::TwoWheeler),
    ("scooter", ObjectClass::TwoWheeler),
];

impl ObjectClass {
    /// The class a label names: `car`, `pedestrian` or `two_wheeler` (the class names), or a
    /// name other data sets and stacks give the same kind of object, in any letter case, with
    /// `-` or a space for `_`, surrounding white space ignored. A van, truck, bus or trailer is
    /// tracked as a car; a person as a pedestrian; a bicycle, cyclist, motorcycle or scooter as
    /// a two-wheeler. `None` for anything else. Allocates nothing.
    pub fn from_label(label: &str) -> Option<Self> {
        let label = label.trim();
        if label.len() > MAX_LABEL_BYTES {
            return None;
        }
        let mut normalised = [0u8; MAX_LABEL_BYTES];
        for (byte, out) in label.bytes().zip(normalised.iter_mut()) {
            *out = match byte {
                b'-' | b' ' => b'_',
                other => other.to_ascii_lowercase(),
            };
        }
        let normalised = &normalised[..label.len()];
        LABELS.iter().find(|(name, _)| name.as_bytes() == normalised).map(|&(_, class)| class)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_names_and_other_data_sets_names_read_as_the_classes_in_any_case() {
        for class in ObjectClass::ALL {
            assert_eq!(ObjectClass::from_label(class.name()), Some(class));
        }
        for (label, class) in [
            ("Truck", ObjectClass::Car),
            (" BUS ", ObjectClass::Car),
            ("passenger-car", ObjectClass::Car),
            ("Large Vehicle", ObjectClass::Car),
            ("Pedestrian Group", ObjectClass::Pedestrian),
            ("PERSON", ObjectClass::Pedestrian),
            ("Bicycle", ObjectClass::TwoWheeler),
            ("two-wheeler", ObjectClass::TwoWheeler),
            ("Two Wheeler", ObjectClass::TwoWheeler),
        ] {
            assert_eq!(ObjectClass::from_label(label), Some(class), "{label}");
        }
    }

    #[test]
    fn unknown_empty_overlong_and_non_ascii_labels_name_no_class() {
        let long = "car_".repeat(20);
        for label in
            ["", "  ", "c a r", "cars", "tram", "carx", "ca", "pedestrians", long.as_str(), "cär", "CAR\0"]
        {
            assert_eq!(ObjectClass::from_label(label), None, "{label:?}");
        }
    }
}
