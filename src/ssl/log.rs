//! The league's log file (as ssl-logtools and the game controller's recorder write it): the
//! header `SSL_LOG_FILE`, format version 1, then each message as its receive time (ns), its
//! type and its size, big-endian, and its bytes. Log players and analysis tools of the teams
//! read it. omniloop stamps each message with simulated time, so a lockstep run's log is
//! byte-identical for the same command stream.

use std::io::{self, Write};

/// The kind of a logged message (the log format's numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogMessage {
    /// An `SSL_WrapperPacket` (vision, 2014 format).
    Vision2014 = 2,
    /// A `Referee` packet (2013 format).
    Referee2013 = 3,
}

/// Writes a log, message by message.
pub struct SslLog<W: Write> {
    out: W,
}

impl<W: Write> SslLog<W> {
    /// A log into `out`, its header written.
    pub fn new(mut out: W) -> io::Result<Self> {
        out.write_all(b"SSL_LOG_FILE")?;
        out.write_all(&1i32.to_be_bytes())?;
        Ok(Self { out })
    }

    /// One message, received at `t_s` (simulated time).
    pub fn write(&mut self, t_s: f64, kind: LogMessage, bytes: &[u8]) -> io::Result<()> {
        let ns = (t_s * 1e9).round() as i64;
        let len = i32::try_from(bytes.len()).map_err(io::Error::other)?;
        self.out.write_all(&ns.to_be_bytes())?;
        self.out.write_all(&(kind as i32).to_be_bytes())?;
        self.out.write_all(&len.to_be_bytes())?;
        self.out.write_all(bytes)
    }

    /// Flushes and gives back the writer.
    pub fn finish(mut self) -> io::Result<W> {
        self.out.flush()?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_message_follows_the_header_with_its_time_kind_and_size() {
        let mut log = SslLog::new(Vec::new()).unwrap();
        log.write(1.5, LogMessage::Referee2013, &[7, 8]).unwrap();
        let b = log.finish().unwrap();
        assert_eq!(&b[..12], b"SSL_LOG_FILE");
        assert_eq!(&b[12..16], &[0, 0, 0, 1]);
        assert_eq!(
            i64::from_be_bytes(b[16..24].try_into().unwrap()),
            1_500_000_000
        );
        assert_eq!(&b[24..28], &[0, 0, 0, 3]);
        assert_eq!(&b[28..32], &[0, 0, 0, 2]);
        assert_eq!(&b[32..], &[7, 8]);
    }
}
