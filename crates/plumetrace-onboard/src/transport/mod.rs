//! How a vehicle's lines travel: connections ([`conn`]: TCP or a serial device), line framing
//! ([`lines`]), serial lines and pseudo-terminals ([`serial`]), and the link that carries a line
//! protocol over them ([`line_link`]: reconnection, counts, the traffic log).

pub mod conn;
pub mod line_link;
pub mod lines;
pub mod serial;
