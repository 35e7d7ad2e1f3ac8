//! The links an onboard file describes: the vehicle link (Bluefin on TCP, Iver on a serial line,
//! MOOS with the `moos` feature) and the separate chemical and current-meter inputs.

use super::RunError;
use crate::config::{LinkFile, Onboard, ProtocolKind, RunMode, SafeAction};
use crate::link::{Link, LinkTiming};
use crate::protocol::iver::Units;
use crate::protocol::session::{Bluefin, BluefinSettings, ChemOnly, Iver, IverSettings, Protocol};
use crate::transport::conn::Endpoint;
use crate::transport::line_link::LineLink;
use std::io::Write;
use std::time::Duration;

/// The link timing an onboard file sets.
fn timing(l: &LinkFile) -> LinkTiming {
    let secs = Duration::from_secs_f64;
    LinkTiming {
        silence_timeout: secs(l.silence_timeout_s),
        reconnect_min: secs(l.reconnect_min_s),
        reconnect_max: secs(l.reconnect_max_s),
    }
}

/// Makes the link an onboard file describes; raw traffic goes to `traffic`. An error when the
/// file asks for a link this build does not have (MOOS without the `moos` feature).
pub fn link_for(
    onboard: &Onboard,
    traffic: Option<Box<dyn Write + Send>>,
) -> Result<Box<dyn Link>, RunError> {
    let l = &onboard.file.link;
    let secs = Duration::from_secs_f64;
    let safe_stop = l.safe_command == SafeAction::Stop;
    let (endpoint, protocol): (Endpoint, Box<dyn Protocol>) = match l.protocol {
        ProtocolKind::Bluefin => (
            Endpoint::Tcp(l.address.clone().unwrap_or_default()),
            Box::new(Bluefin::new(BluefinSettings {
                ack_timeout: secs(l.ack_timeout_s),
                ack_tries: l.ack_tries,
                status_period: secs(l.status_period_s),
                safe_stop,
            })),
        ),
        ProtocolKind::Iver => (
            Endpoint::Serial {
                path: l.device.clone().unwrap_or_default(),
                baud: l.baud,
            },
            Box::new(Iver::new(IverSettings {
                units: Units {
                    remote_helm_major: l.remote_helm_major.unwrap_or(5),
                },
                poll_period: secs(l.poll_period_s),
                oms_timeout_s: l.oms_timeout_s,
                max_pitch_deg: 45.0,
                safe_stop,
            })),
        ),
        #[cfg(feature = "moos")]
        ProtocolKind::Moos => {
            return crate::moos::link::MoosLink::for_onboard(onboard, timing(l), traffic)
                .map(|m| Box::new(m) as Box<dyn Link>)
                .map_err(RunError::from);
        }
        #[cfg(not(feature = "moos"))]
        ProtocolKind::Moos => return Err(RunError::MoosMissing),
    };
    let c = &onboard.file.chemical;
    let on_link = c.address.is_none() && c.device.is_none();
    let mut link = LineLink::new(
        endpoint,
        protocol,
        on_link.then(|| c.line_format()),
        timing(l),
        traffic,
    );
    if let Some(f) = onboard
        .file
        .flow
        .as_ref()
        .filter(|f| f.address.is_none() && f.device.is_none())
    {
        link = link.with_flow(f.line_format());
    }
    link.set_lock_step(onboard.file.run.mode == RunMode::LockStep);
    Ok(Box::new(link))
}

/// Where the current meter's lines come from when not on the vehicle link.
fn flow_endpoint(onboard: &Onboard) -> Option<Endpoint> {
    let f = onboard.file.flow.as_ref()?;
    match (&f.address, &f.device) {
        (Some(a), _) => Some(Endpoint::Tcp(a.clone())),
        (None, Some(d)) => Some(Endpoint::Serial {
            path: d.clone(),
            baud: onboard.file.link.baud,
        }),
        (None, None) => None,
    }
}

/// The separate current-meter input an onboard file names (`flow.address` or `flow.device`),
/// unless it is the chemical input's too (then that input carries both); its raw lines go to
/// `traffic`.
pub fn flow_link_for(
    onboard: &Onboard,
    traffic: Option<Box<dyn Write + Send>>,
) -> Option<LineLink> {
    let endpoint = flow_endpoint(onboard)?;
    if chem_endpoint(onboard).as_ref() == Some(&endpoint) {
        return None;
    }
    let f = onboard.file.flow.as_ref()?;
    Some(
        LineLink::new(
            endpoint,
            Box::new(ChemOnly),
            None,
            timing(&onboard.file.link),
            traffic,
        )
        .with_flow(f.line_format()),
    )
}

fn chem_endpoint(onboard: &Onboard) -> Option<Endpoint> {
    let c = &onboard.file.chemical;
    match (&c.address, &c.device) {
        (Some(a), _) => Some(Endpoint::Tcp(a.clone())),
        (None, Some(d)) => Some(Endpoint::Serial {
            path: d.clone(),
            baud: onboard.file.link.baud,
        }),
        (None, None) => None,
    }
}

/// The separate chemical input an onboard file names (`chemical.address` or
/// `chemical.device`), if any; its raw lines go to `traffic`.
pub fn chem_link_for(
    onboard: &Onboard,
    traffic: Option<Box<dyn Write + Send>>,
) -> Option<LineLink> {
    let c = &onboard.file.chemical;
    let endpoint = chem_endpoint(onboard)?;
    let shared = flow_endpoint(onboard).as_ref() == Some(&endpoint);
    let mut link = LineLink::new(
        endpoint,
        Box::new(ChemOnly),
        Some(c.line_format()),
        timing(&onboard.file.link),
        traffic,
    );
    if let Some(f) = onboard.file.flow.as_ref().filter(|_| shared) {
        link = link.with_flow(f.line_format());
    }
    Some(link)
}
