//! Debug probes: listing them, and choosing the one to flash through (`--probe`), with the
//! errors a person can act on: none attached, several, one this user may not open.

use anyhow::Result;
use probe_rs::probe::list::{Accessibility, Lister, ProbeListItem};
use probe_rs::probe::{DebugProbeInfo, DebugProbeSelector};
use serde::Serialize;

use crate::rig::{Exit, Failure};

/// What to do when a probe is attached but this user may not open it (Linux): probe-rs's
/// udev rules.
pub const UDEV_HINT: &str = "install probe-rs's udev rules, 69-probe-rs.rules \
    (https://probe.rs/docs/getting-started/probe-setup/), into /etc/udev/rules.d/, run \
    `sudo udevadm control --reload && sudo udevadm trigger`, then unplug and replug the board";

/// One probe as `kapitza probes` shows it.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ProbeView {
    /// `VID:PID[:SERIAL]`, as `--probe` takes it.
    pub selector: String,
    pub name: String,
    pub vid: u16,
    pub pid: u16,
    pub serial_number: Option<String>,
    /// The driver probe-rs uses for it (`ST-LINK`, `CMSIS-DAP`, …).
    pub kind: String,
    /// This user may open it.
    pub accessible: bool,
}

impl ProbeView {
    pub fn new(item: &ProbeListItem) -> Self {
        let i = &item.info;
        Self {
            selector: selector_text(i),
            name: i.identifier.clone(),
            vid: i.vendor_id,
            pid: i.product_id,
            serial_number: i.serial_number.clone(),
            kind: i.probe_type(),
            accessible: item.accessibility == Accessibility::Accessible,
        }
    }

    pub fn line(&self) -> String {
        format!(
            "{}  {} ({}){}",
            self.selector,
            self.name,
            self.kind,
            if self.accessible {
                ""
            } else {
                "  [no permission]"
            }
        )
    }
}

fn selector_text(i: &DebugProbeInfo) -> String {
    match &i.serial_number {
        Some(s) => format!("{:04x}:{:04x}:{s}", i.vendor_id, i.product_id),
        None => format!("{:04x}:{:04x}", i.vendor_id, i.product_id),
    }
}

/// Every probe attached.
pub fn list(lister: &Lister) -> Vec<ProbeView> {
    lister
        .list_all_with_access()
        .iter()
        .map(ProbeView::new)
        .collect()
}

/// Parses `--probe VID:PID[:SERIAL]` (hexadecimal IDs).
pub fn parse_selector(s: &str) -> Result<DebugProbeSelector> {
    s.parse().map_err(|e| {
        anyhow::anyhow!("--probe {s:?}: {e}; expected VID:PID[:SERIAL], e.g. 0483:374e")
    })
}

/// The one probe to flash through: the only one attached, or the one `selector` names.
pub fn select(lister: &Lister, selector: Option<&DebugProbeSelector>) -> Result<DebugProbeInfo> {
    let found = lister.list_with_access(selector);
    let item = match found.as_slice() {
        [one] => one,
        [] => {
            let msg = match selector {
                Some(s) => {
                    let all = list(lister);
                    format!(
                        "no debug probe matches --probe {s}; attached: {}",
                        if all.is_empty() {
                            "none".to_string()
                        } else {
                            all.iter()
                                .map(|p| p.selector.clone())
                                .collect::<Vec<_>>()
                                .join(", ")
                        }
                    )
                }
                None => {
                    "no debug probe found. Plug the NUCLEO's ST-LINK USB port (CN1) into this \
                         computer; `kapitza probes` lists the probes \
                         seen. On Linux a probe this user may not open can also go unseen: "
                        .to_string()
                        + UDEV_HINT
                }
            };
            return Err(Failure::new(Exit::NoRig, msg).into());
        }
        many => {
            let lines: Vec<String> = many
                .iter()
                .map(|p| format!("  {}", ProbeView::new(p).line()))
                .collect();
            return Err(Failure::new(
                Exit::NoRig,
                format!(
                    "{} debug probes are attached; choose one with --probe VID:PID[:SERIAL]:\n{}",
                    many.len(),
                    lines.join("\n")
                ),
            )
            .into());
        }
    };
    if item.accessibility == Accessibility::PermissionDenied {
        return Err(permission_denied(&item.info));
    }
    Ok(item.info.clone())
}

/// The error for a probe this user may not open.
pub fn permission_denied(info: &DebugProbeInfo) -> anyhow::Error {
    Failure::new(
        Exit::NoRig,
        format!(
            "the debug probe {} ({}) is attached, but this user may not open it: {UDEV_HINT}",
            selector_text(info),
            info.identifier
        ),
    )
    .into()
}
