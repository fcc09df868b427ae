//! A capture "bus": an `SpiDevice` and a D/C `OutputPin` that record what a
//! display driver sends, instead of driving a panel, and a decoder that turns
//! a recording back into the panel window and its RGB565 pixels.
//!
//! The host tests record into memory; the firmware records into a host file
//! over semihosting, so the bytes its display path sent can be checked
//! against the host's image.
//!
//! # Recording format
//! One record per SPI write: the D/C level (`0` command, `1` data), the
//! length as a little-endian u32, then the bytes.

use core::cell::RefCell;
use core::convert::Infallible;
use core::fmt;

use embedded_hal::digital::{ErrorType as PinErrorType, OutputPin};
use embedded_hal::spi::{self, ErrorType as SpiErrorType, Operation, SpiDevice};

use crate::display::{CASET, RAMWR, RASET};

/// Where a recording goes.
pub trait ByteSink {
    /// Why a write failed.
    type Error: fmt::Debug;
    /// Append `bytes`.
    ///
    /// # Errors
    /// The sink's own.
    fn put(&mut self, bytes: &[u8]) -> Result<(), Self::Error>;
}

/// The shared state of a capture bus: the sink and the D/C level.
#[derive(Debug)]
pub struct CaptureBus<W> {
    state: RefCell<(W, bool)>,
}

impl<W: ByteSink> CaptureBus<W> {
    /// A bus recording into `sink`, D/C low.
    pub fn new(sink: W) -> Self {
        Self {
            state: RefCell::new((sink, false)),
        }
    }

    /// The SPI device side.
    pub fn spi(&self) -> CaptureSpi<'_, W> {
        CaptureSpi { bus: self }
    }

    /// The D/C pin side.
    pub fn dc(&self) -> CapturePin<'_, W> {
        CapturePin { bus: self }
    }

    /// The sink, with everything recorded.
    pub fn into_inner(self) -> W {
        self.state.into_inner().0
    }
}

/// Why the capture SPI failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaptureError {
    /// A read was asked for: a display sink only writes.
    ReadUnsupported,
    /// The sink refused the bytes.
    Sink,
    /// A write longer than `u32::MAX` bytes.
    TooLong,
}

impl spi::Error for CaptureError {
    fn kind(&self) -> spi::ErrorKind {
        spi::ErrorKind::Other
    }
}

/// The SPI device of a [`CaptureBus`].
#[derive(Debug)]
pub struct CaptureSpi<'a, W> {
    bus: &'a CaptureBus<W>,
}

impl<W: ByteSink> SpiErrorType for CaptureSpi<'_, W> {
    type Error = CaptureError;
}

impl<W: ByteSink> SpiDevice for CaptureSpi<'_, W> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), CaptureError> {
        let mut state = self.bus.state.borrow_mut();
        let (sink, dc) = &mut *state;
        for op in operations {
            match op {
                Operation::Write(bytes) => {
                    let len = u32::try_from(bytes.len()).map_err(|_| CaptureError::TooLong)?;
                    sink.put(&[*dc as u8]).map_err(|_| CaptureError::Sink)?;
                    sink.put(&len.to_le_bytes())
                        .map_err(|_| CaptureError::Sink)?;
                    sink.put(bytes).map_err(|_| CaptureError::Sink)?;
                }
                Operation::DelayNs(_) => {}
                Operation::Read(_) | Operation::Transfer(..) | Operation::TransferInPlace(_) => {
                    return Err(CaptureError::ReadUnsupported)
                }
            }
        }
        Ok(())
    }
}

/// The D/C pin of a [`CaptureBus`].
#[derive(Debug)]
pub struct CapturePin<'a, W> {
    bus: &'a CaptureBus<W>,
}

impl<W> PinErrorType for CapturePin<'_, W> {
    type Error = Infallible;
}

impl<W> OutputPin for CapturePin<'_, W> {
    fn set_low(&mut self) -> Result<(), Infallible> {
        self.bus.state.borrow_mut().1 = false;
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Infallible> {
        self.bus.state.borrow_mut().1 = true;
        Ok(())
    }
}

/// The panel window and pixel count a recording drew.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DecodedFrame {
    /// First and last column.
    pub columns: (u16, u16),
    /// First and last row.
    pub rows: (u16, u16),
    /// Pixels written (RGB565), row-major.
    pub pixels: usize,
}

/// Why a recording does not decode to one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeError {
    /// A record runs past the end.
    Truncated {
        /// Offset of the record.
        offset: usize,
    },
    /// A D/C byte other than 0 or 1.
    BadLevel {
        /// Offset of the record.
        offset: usize,
    },
    /// A command record that is not exactly one byte.
    BadCommandLength {
        /// Offset of the record.
        offset: usize,
    },
    /// A command this decoder does not know.
    UnknownCommand {
        /// The command byte.
        command: u8,
    },
    /// `CASET` or `RASET` without exactly 4 parameter bytes, or last < first.
    BadRange {
        /// The command.
        command: u8,
    },
    /// Data before any command.
    DataWithoutCommand,
    /// Pixels other than the window's area, an odd byte count, or more
    /// pixels than the output holds.
    PixelCount {
        /// Bytes of pixel data.
        bytes: usize,
        /// Pixels the window holds.
        expected: usize,
    },
    /// No `CASET`, `RASET` or `RAMWR`.
    Incomplete,
}

/// Decode a recording of one frame: the window from `CASET`/`RASET`, and
/// the RGB565 pixels after `RAMWR` into `pixels`.
///
/// # Errors
/// [`DecodeError`] for anything but exactly one well-formed frame.
pub fn decode_frame(recording: &[u8], pixels: &mut [u16]) -> Result<DecodedFrame, DecodeError> {
    let (mut command, mut columns, mut rows) = (None::<u8>, None, None);
    let mut params = heapless::Vec::<u8, 4>::new();
    let mut pixel_bytes = 0usize;
    let mut pending = None::<u8>;
    let mut at = 0usize;
    let finish_params = |command: Option<u8>, params: &[u8]| {
        let cmd = command.unwrap_or(0);
        let &[f0, f1, l0, l1] = params else {
            return Err(DecodeError::BadRange { command: cmd });
        };
        let first = u16::from_be_bytes([f0, f1]);
        let last = u16::from_be_bytes([l0, l1]);
        if last < first {
            return Err(DecodeError::BadRange { command: cmd });
        }
        Ok((first, last))
    };
    while at < recording.len() {
        let header = recording
            .get(at..at + 5)
            .ok_or(DecodeError::Truncated { offset: at })?;
        let level = header[0];
        let len = u32::from_le_bytes([header[1], header[2], header[3], header[4]]) as usize;
        let body = recording
            .get(at + 5..at + 5 + len)
            .ok_or(DecodeError::Truncated { offset: at })?;
        match level {
            0 => {
                if len != 1 {
                    return Err(DecodeError::BadCommandLength { offset: at });
                }
                match command {
                    Some(CASET) => columns = Some(finish_params(command, &params)?),
                    Some(RASET) => rows = Some(finish_params(command, &params)?),
                    _ => {}
                }
                let cmd = body[0];
                if ![CASET, RASET, RAMWR].contains(&cmd) {
                    return Err(DecodeError::UnknownCommand { command: cmd });
                }
                command = Some(cmd);
                params.clear();
            }
            1 => match command {
                None => return Err(DecodeError::DataWithoutCommand),
                Some(CASET) | Some(RASET) => {
                    params
                        .extend_from_slice(body)
                        .map_err(|_| DecodeError::BadRange {
                            command: command.unwrap_or(0),
                        })?;
                }
                Some(_) => {
                    for &b in body {
                        match pending.take() {
                            None => pending = Some(b),
                            Some(hi) => {
                                let index = pixel_bytes / 2;
                                let capacity = pixels.len();
                                let slot =
                                    pixels.get_mut(index).ok_or(DecodeError::PixelCount {
                                        bytes: pixel_bytes + 2,
                                        expected: capacity,
                                    })?;
                                *slot = u16::from_be_bytes([hi, b]);
                            }
                        }
                        pixel_bytes += 1;
                    }
                }
            },
            _ => return Err(DecodeError::BadLevel { offset: at }),
        }
        at += 5 + len;
    }
    match command {
        Some(CASET) => columns = Some(finish_params(command, &params)?),
        Some(RASET) => rows = Some(finish_params(command, &params)?),
        _ => {}
    }
    let (Some(columns), Some(rows), Some(RAMWR)) = (columns, rows, command) else {
        return Err(DecodeError::Incomplete);
    };
    let expected = (columns.1 - columns.0 + 1) as usize * (rows.1 - rows.0 + 1) as usize;
    if pixel_bytes != 2 * expected {
        return Err(DecodeError::PixelCount {
            bytes: pixel_bytes,
            expected,
        });
    }
    Ok(DecodedFrame {
        columns,
        rows,
        pixels: expected,
    })
}
