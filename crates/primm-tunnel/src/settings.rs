//! The zenoh side of a tunnel: which sessions it reaches and how.

use std::path::PathBuf;

/// A zenoh session's role.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZenohMode {
    /// Talks to other peers directly (zenoh's default).
    Peer,
    /// Routes for clients and other routers.
    Router,
    /// Reaches the others only through a router.
    Client,
}

impl ZenohMode {
    /// The name zenoh's configuration uses (`peer`, `router`, `client`).
    pub fn id(self) -> &'static str {
        match self {
            Self::Peer => "peer",
            Self::Router => "router",
            Self::Client => "client",
        }
    }

    /// The mode named `id`.
    pub fn from_id(id: &str) -> Option<Self> {
        [Self::Peer, Self::Router, Self::Client].into_iter().find(|mode| mode.id() == id)
    }
}

impl std::fmt::Display for ZenohMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.id())
    }
}

/// What a tunnel's zenoh session is configured with. Everything left unset keeps the value of
/// [`config_file`](Self::config_file), or zenoh's default without one (peer mode, listening on
/// every interface, multicast scouting on).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ZenohSettings {
    /// A zenoh configuration file (JSON5) to start from.
    pub config_file: Option<PathBuf>,
    /// The session's role.
    pub mode: Option<ZenohMode>,
    /// Endpoints to listen on, e.g. `tcp/0.0.0.0:7447`.
    pub listen: Vec<String>,
    /// Endpoints to connect to, e.g. `tcp/192.168.1.20:7447`.
    pub connect: Vec<String>,
    /// Whether to find peers by UDP multicast; `Some(false)` keeps the session to its
    /// endpoints.
    pub multicast_scouting: Option<bool>,
    /// What a full transmission queue does to a frame: wait for room (`true`) or drop it
    /// (`false`, zenoh's default for publications). Waiting keeps the tunnel lossless through
    /// short congestion; the local subscriber buffers of the streams absorb the wait, and a
    /// longer one overflows them, which the far side's sequence gaps show.
    pub block_when_congested: bool,
}

impl Default for ZenohSettings {
    fn default() -> Self {
        Self {
            config_file: None,
            mode: None,
            listen: Vec::new(),
            connect: Vec::new(),
            multicast_scouting: None,
            block_when_congested: true,
        }
    }
}

/// Why a zenoh configuration could not be made.
#[derive(Debug, thiserror::Error)]
pub enum ZenohConfigError {
    /// The configuration file could not be read or parsed.
    #[error("cannot load the zenoh configuration {path}: {reason}")]
    File {
        /// The file.
        path: PathBuf,
        /// zenoh's reason.
        reason: String,
    },
    /// zenoh refused a value (e.g. an endpoint that is not `PROTOCOL/ADDRESS`).
    #[error("zenoh refuses {key} = {value}: {reason}")]
    Value {
        /// The configuration key.
        key: &'static str,
        /// The value, as JSON.
        value: String,
        /// zenoh's reason.
        reason: String,
    },
}

impl ZenohSettings {
    /// A session that stays on the loopback interface: it listens on `listen_port` and/or
    /// connects to `connect_port` on 127.0.0.1 over TCP, with multicast scouting off, in peer
    /// mode. Two tunnels on one machine (the demo's two "hosts", the tests) use it.
    pub fn loopback(listen_port: Option<u16>, connect_port: Option<u16>) -> Self {
        let endpoint = |port: u16| format!("tcp/127.0.0.1:{port}");
        Self {
            config_file: None,
            mode: Some(ZenohMode::Peer),
            listen: listen_port.map(endpoint).into_iter().collect(),
            connect: connect_port.map(endpoint).into_iter().collect(),
            multicast_scouting: Some(false),
            block_when_congested: true,
        }
    }

    /// The zenoh configuration.
    pub fn zenoh_config(&self) -> Result<zenoh::Config, ZenohConfigError> {
        let mut config = match &self.config_file {
            Some(path) => zenoh::Config::from_file(path).map_err(|reason| ZenohConfigError::File {
                path: path.clone(),
                reason: reason.to_string(),
            })?,
            None => zenoh::Config::default(),
        };
        let mut set = |key: &'static str, value: String| {
            config.insert_json5(key, &value).map_err(|reason| ZenohConfigError::Value {
                key,
                value,
                reason: reason.to_string(),
            })
        };
        if let Some(mode) = self.mode {
            set("mode", json_string(mode.id()))?;
        }
        if !self.listen.is_empty() {
            set("listen/endpoints", json_strings(&self.listen))?;
        }
        if !self.connect.is_empty() {
            set("connect/endpoints", json_strings(&self.connect))?;
        }
        if let Some(enabled) = self.multicast_scouting {
            set("scouting/multicast/enabled", enabled.to_string())?;
        }
        if self.block_when_congested {
            set(
                "qos/publication",
                r#"[{"key_exprs": ["**"], "config": {"congestion_control": "block"}}]"#.to_owned(),
            )?;
        }
        Ok(config)
    }
}

fn json_string(text: &str) -> String {
    serde_json::Value::from(text).to_string()
}

fn json_strings(texts: &[String]) -> String {
    serde_json::Value::from(texts.to_vec()).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_mode_is_found_by_its_id() {
        for mode in [ZenohMode::Peer, ZenohMode::Router, ZenohMode::Client] {
            assert_eq!(ZenohMode::from_id(mode.id()), Some(mode));
        }
        assert_eq!(ZenohMode::from_id("broker"), None);
    }

    #[test]
    fn loopback_settings_make_a_configuration_zenoh_accepts() {
        let config = ZenohSettings::loopback(Some(7447), Some(7448)).zenoh_config().unwrap();
        let text = format!("{config}");
        assert!(text.contains("tcp/127.0.0.1:7447"), "{text}");
        assert!(text.contains("tcp/127.0.0.1:7448"), "{text}");
        assert!(text.contains("block"), "congestion control set to block: {text}");
    }

    #[test]
    fn a_malformed_endpoint_is_refused_with_its_key() {
        let settings =
            ZenohSettings { listen: vec!["no protocol here".to_owned()], ..ZenohSettings::default() };
        match settings.zenoh_config() {
            Err(ZenohConfigError::Value { key, .. }) => assert_eq!(key, "listen/endpoints"),
            other => panic!("expected a refused value, got {other:?}"),
        }
    }

    #[test]
    fn a_missing_configuration_file_is_reported_with_its_path() {
        let settings = ZenohSettings {
            config_file: Some("/nonexistent/zenoh.json5".into()),
            ..ZenohSettings::default()
        };
        match settings.zenoh_config() {
            Err(ZenohConfigError::File { path, .. }) => {
                assert_eq!(path, PathBuf::from("/nonexistent/zenoh.json5"))
            }
            other => panic!("expected a file error, got {other:?}"),
        }
    }
}
