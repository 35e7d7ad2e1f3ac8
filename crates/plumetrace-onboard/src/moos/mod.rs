//! A MOOS community client (the `moos` feature): the planner as a MOOS application, reading
//! `NAV_*` and the chemical variable from a MOOSDB and publishing `DESIRED_*`, so it can be the
//! backseat driver of a MOOS-IvP vehicle.
//!
//! - [`wire`]: the wire format (messages, packets, the handshake's bytes, the bounds on what
//!   arrives) and the framer;
//! - [`nav`]: navigation assembled from the postings;
//! - [`link`]: the client as a vehicle link (handshake, registrations, timing and skew,
//!   reconnection, what it publishes);
//! - [`view`]: what pMarineViewer draws of the planner (`VIEW_POLYGON` or `VIEW_SEGLIST`,
//!   `VIEW_MARKER`, `VIEW_POINT`).
//!
//! # Variables
//!
//! Read (registered with interval 0): `NAV_X`, `NAV_Y` (m; MOOS's local frame, x east and y
//! north of the community's `LatOrigin`/`LongOrigin`, the same convention as plumetrace's
//! frame), `NAV_HEADING` (degrees clockwise from north, as plumetrace's headings), `NAV_SPEED`
//! (m/s), `NAV_DEPTH`, `NAV_ALTITUDE` (m, optional), the configured chemical variable and
//! `MOOS_MANUAL_OVERRIDE` (`true`: the planner pauses, as for a front seat that does not accept
//! commands). A navigation record is complete when both `NAV_X` and `NAV_Y` have been updated
//! since the last one and a heading and a speed are known; it takes the latest depth and
//! altitude. MOOS navigation never counts as a GPS fix. The positions pass the runner as
//! latitude and longitude about `link.origin` and come back to the same metres (the geodesic
//! round trip is exact to micrometres), so the op-area is written in the community's x and y.
//!
//! Published: `DESIRED_HEADING` (deg), `DESIRED_SPEED` (m/s), `DESIRED_DEPTH` (m; an altitude
//! hold goes out as the depth that leaves that altitude over the last `NAV_DEPTH` plus
//! `NAV_ALTITUDE`, and without both no depth goes out), `CPT_BEHAVIOUR`, `CPT_DETECTION`,
//! `CPT_DECLARATION`, `CPT_STATUS` (the names and values of the `.alog` writer,
//! [`plumetrace_log::alog`]), `CPT_PAUSED` (`true` when the planner pauses, `false` when it
//! steers again), and for pMarineViewer the op-area and subregions (`VIEW_POLYGON`, or
//! `VIEW_SEGLIST` for one that is not convex, at each connection), the source estimate and the
//! declarations (`VIEW_MARKER`) and the lost points (`VIEW_POINT`). The safe command
//! (`link.safe_command = "stop"`) is `DESIRED_SPEED = 0`; at the end of a run the safe command
//! goes out and `CPT_STATUS = ended`. No flow (current) variable is read: the runner
//! takes no flow from any link yet.

pub mod link;
pub mod nav;
pub mod view;
pub mod wire;
