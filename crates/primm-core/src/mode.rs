//! The four IMM modes, sets of active modes, and the six methods of the paper's tables.

/// Number of modes primm knows.
pub const MODE_COUNT: usize = 4;

/// One IMM mode. The order (`PR, CV, CA, CT`) is the order of every per-mode vector and matrix
/// in primm: configuration, mode probabilities and output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Mode {
    /// PR: the learned displacement predictor (paper, Section III-C), state `[x, y]`.
    #[cfg_attr(feature = "serde", serde(rename = "pr"))]
    Learned = 0,
    /// CV: constant velocity (`eq:cv_F`), state `[x, y, vx, vy]`.
    #[cfg_attr(feature = "serde", serde(rename = "cv"))]
    ConstantVelocity = 1,
    /// CA: constant acceleration (`eq:ca_F`), state `[x, y, vx, vy, ax, ay]`.
    #[cfg_attr(feature = "serde", serde(rename = "ca"))]
    ConstantAcceleration = 2,
    /// CT: coordinated turn (`eq:ct_x` … `eq:ct_vy`), state `[x, y, vx, vy, ω]`.
    #[cfg_attr(feature = "serde", serde(rename = "ct"))]
    CoordinatedTurn = 3,
}

impl Mode {
    /// All modes in primm's order.
    pub const ALL: [Mode; MODE_COUNT] =
        [Mode::Learned, Mode::ConstantVelocity, Mode::ConstantAcceleration, Mode::CoordinatedTurn];

    /// Index of the mode in per-mode arrays.
    pub fn index(self) -> usize {
        self as usize
    }

    /// Short id used in configuration and output (`pr`, `cv`, `ca`, `ct`).
    pub fn id(self) -> &'static str {
        match self {
            Mode::Learned => "pr",
            Mode::ConstantVelocity => "cv",
            Mode::ConstantAcceleration => "ca",
            Mode::CoordinatedTurn => "ct",
        }
    }
}

/// A set of modes, as a bit mask indexed by [`Mode::index`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct ModeSet(u8);

impl ModeSet {
    /// No mode.
    pub const EMPTY: ModeSet = ModeSet(0);
    /// All four modes (PR-IMM).
    pub const ALL: ModeSet = ModeSet(0b1111);

    /// The set of the given modes.
    pub fn of(modes: &[Mode]) -> Self {
        modes.iter().fold(Self::EMPTY, |set, &mode| set.with(mode))
    }

    /// This set plus `mode`.
    pub fn with(self, mode: Mode) -> Self {
        ModeSet(self.0 | (1 << mode.index()))
    }

    /// This set without `mode`.
    pub fn without(self, mode: Mode) -> Self {
        ModeSet(self.0 & !(1 << mode.index()))
    }

    /// Whether `mode` is in the set.
    pub fn contains(self, mode: Mode) -> bool {
        self.0 & (1 << mode.index()) != 0
    }

    /// Number of modes in the set.
    pub fn len(self) -> usize {
        self.0.count_ones() as usize
    }

    /// Whether the set is empty.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The modes of the set in primm's order.
    pub fn iter(self) -> impl Iterator<Item = Mode> {
        Mode::ALL.into_iter().filter(move |&mode| self.contains(mode))
    }
}

#[cfg(feature = "serde")]
impl serde::Serialize for ModeSet {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_seq(self.iter())
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for ModeSet {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let modes = alloc::vec::Vec::<Mode>::deserialize(deserializer)?;
        Ok(ModeSet::of(&modes))
    }
}

/// The six methods compared in the paper's Section IV, each a set of active modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Method {
    /// Constant-velocity Kalman filter.
    #[cfg_attr(feature = "serde", serde(rename = "cv"))]
    ConstantVelocity,
    /// Constant-acceleration Kalman filter.
    #[cfg_attr(feature = "serde", serde(rename = "ca"))]
    ConstantAcceleration,
    /// Coordinated-turn extended Kalman filter.
    #[cfg_attr(feature = "serde", serde(rename = "ct"))]
    CoordinatedTurn,
    /// The learned predictor alone.
    #[cfg_attr(feature = "serde", serde(rename = "pr"))]
    Learned,
    /// IMM of CV, CA and CT.
    #[cfg_attr(feature = "serde", serde(rename = "imm"))]
    Imm,
    /// IMM of PR, CV, CA and CT.
    #[cfg_attr(feature = "serde", serde(rename = "pr-imm"))]
    PrImm,
}

impl Method {
    /// All methods in the order of the paper's tables.
    pub const ALL: [Method; 6] = [
        Method::ConstantVelocity,
        Method::ConstantAcceleration,
        Method::CoordinatedTurn,
        Method::Learned,
        Method::Imm,
        Method::PrImm,
    ];

    /// The active modes of the method.
    pub fn modes(self) -> ModeSet {
        match self {
            Method::ConstantVelocity => ModeSet::of(&[Mode::ConstantVelocity]),
            Method::ConstantAcceleration => ModeSet::of(&[Mode::ConstantAcceleration]),
            Method::CoordinatedTurn => ModeSet::of(&[Mode::CoordinatedTurn]),
            Method::Learned => ModeSet::of(&[Mode::Learned]),
            Method::Imm => {
                ModeSet::of(&[Mode::ConstantVelocity, Mode::ConstantAcceleration, Mode::CoordinatedTurn])
            }
            Method::PrImm => ModeSet::ALL,
        }
    }

    /// Short id used on the command line and in reports.
    pub fn id(self) -> &'static str {
        match self {
            Method::ConstantVelocity => "cv",
            Method::ConstantAcceleration => "ca",
            Method::CoordinatedTurn => "ct",
            Method::Learned => "pr",
            Method::Imm => "imm",
            Method::PrImm => "pr-imm",
        }
    }

    /// Parses a short id.
    pub fn from_id(id: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|method| method.id() == id)
    }

    /// Key used in JSON reports and file names (`cv`, …, `pr_imm`).
    pub fn key(self) -> &'static str {
        match self {
            Method::PrImm => "pr_imm",
            other => other.id(),
        }
    }

    /// Display label (`CV`, …, `PR-IMM`).
    pub fn label(self) -> &'static str {
        match self {
            Method::ConstantVelocity => "CV",
            Method::ConstantAcceleration => "CA",
            Method::CoordinatedTurn => "CT",
            Method::Learned => "PR",
            Method::Imm => "IMM",
            Method::PrImm => "PR-IMM",
        }
    }

    /// Row label of the overall tables, which spell out the IMM's modes.
    pub fn row_label(self) -> &'static str {
        match self {
            Method::Imm => "IMM (CV+CA+CT)",
            other => other.label(),
        }
    }

    /// Parses an id, a key or a label, ignoring case.
    pub fn parse(text: &str) -> Option<Method> {
        Self::ALL.into_iter().find(|method| {
            method.id().eq_ignore_ascii_case(text)
                || method.key().eq_ignore_ascii_case(text)
                || method.label().eq_ignore_ascii_case(text)
        })
    }

    /// Whether the method needs the learned predictor.
    pub fn needs_predictor(self) -> bool {
        self.modes().contains(Mode::Learned)
    }
}

impl core::fmt::Display for Method {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.id())
    }
}

/// A method name that is none of `cv`, `ca`, `ct`, `pr`, `imm`, `pr-imm`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown method '{text}' (expected one of cv, ca, ct, pr, imm, pr-imm)")]
pub struct UnknownMethod {
    /// The text that names no method.
    pub text: alloc::string::String,
}

impl core::str::FromStr for Method {
    type Err = UnknownMethod;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::from_id(s).ok_or_else(|| UnknownMethod { text: s.into() })
    }
}
