//! The Small-Size League's wire formats as `prost` structs written from the protocols'
//! documentation with their field numbers (the league's `.proto` files are GPL-3.0 and are
//! not copied): the simulation protocol ([`sim`]), ssl-vision's packets ([`vision`]) and the
//! game controller's referee packet ([`referee`]). All are proto2 without a package.
//!
//! [`decode`] is the one way in from the network: bounded in size, malformed bytes an error
//! naming the message expected. prost fills a required field a datagram leaves out with its
//! default, so the layer above judges the values.

pub mod referee;
pub mod sim;
pub mod vision;

use thiserror::Error;

/// The largest datagram taken, bytes (a UDP datagram over IPv4 holds at most 65,507).
pub const MAX_DATAGRAM: usize = 65_507;

/// Why a datagram was not taken.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum WireError {
    /// Longer than [`MAX_DATAGRAM`].
    #[error("{len} bytes, over the {MAX_DATAGRAM} a datagram may hold")]
    TooLong {
        /// Its length.
        len: usize,
    },
    /// Not the message's encoding.
    #[error("not a {message}: {reason}")]
    Malformed {
        /// The message expected.
        message: &'static str,
        /// prost's reason.
        reason: String,
    },
}

/// Decodes one datagram as `M`, which the protocol names `message`.
pub fn decode<M: prost::Message + Default>(
    bytes: &[u8],
    message: &'static str,
) -> Result<M, WireError> {
    if bytes.len() > MAX_DATAGRAM {
        return Err(WireError::TooLong { len: bytes.len() });
    }
    M::decode(bytes).map_err(|e| WireError::Malformed {
        message,
        reason: e.to_string(),
    })
}

#[cfg(test)]
mod tests;
