//! Bounded logging for conditions that a misbehaving peer can trigger on every frame: the first
//! ten occurrences are logged, then only the 16th, 32nd, 64th, ... so that a flood of bad input
//! costs a logarithmic number of log lines (formatting a log line may allocate; a rejected
//! frame is off the allocation-free path only when it is logged).

/// Counts occurrences and says which ones to log.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LogLimiter {
    occurrences: u64,
}

impl LogLimiter {
    /// Logs every occurrence up to this one.
    pub const ALWAYS_LOGGED: u64 = 10;

    /// Counts one occurrence; whether to log it.
    pub fn occur(&mut self) -> bool {
        self.occurrences += 1;
        self.occurrences <= Self::ALWAYS_LOGGED || self.occurrences.is_power_of_two()
    }

    /// Occurrences so far.
    pub fn occurrences(&self) -> u64 {
        self.occurrences
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn logs_the_first_ten_then_powers_of_two() {
        let mut limiter = LogLimiter::default();
        let logged: Vec<u64> =
            (1..=100).filter(|_| limiter.occur()).collect::<Vec<_>>().iter().map(|&i| i as u64).collect();
        assert_eq!(logged, vec![1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 16, 32, 64]);
        assert_eq!(limiter.occurrences(), 100);
    }
}
