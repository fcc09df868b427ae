//! A generic display sink over `embedded-hal` 1.0: a MIPI DCS panel
//! (ST7789, ILI9341 and kin: 4-wire SPI with a data/command pin, RGB565).
//!
//! A board supplies its HAL's `SpiDevice` and `OutputPin`; nothing else here
//! depends on the chip. A frame is sent as
//! - `CASET` (0x2A) with the first and last column, big-endian u16 each;
//! - `RASET` (0x2B) with the first and last row;
//! - `RAMWR` (0x2C), then the pixels row by row, RGB565 big-endian, one SPI
//!   write per row so that only a row buffer is needed.
//!
//! The command byte goes out with D/C low, parameters and pixels with D/C
//! high. Panel initialisation (sleep out, pixel format, display on) is the
//! board's business and is not sent here.

use core::fmt;

use embedded_hal::digital::OutputPin;
use embedded_hal::spi::SpiDevice;

/// Column address set.
pub const CASET: u8 = 0x2A;
/// Row address set.
pub const RASET: u8 = 0x2B;
/// Memory write.
pub const RAMWR: u8 = 0x2C;

/// Linear map from image values to 8-bit gray: `g = ⌊(v − lo)·gain + ½⌋`,
/// saturated to `0..=255` (NaN gives 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Value shown black.
    pub lo: f32,
    /// Gray levels per unit of value.
    pub gain: f32,
}

impl Window {
    /// The window spanning the image's finite minimum and maximum (black
    /// everywhere if the image is constant or has no finite value).
    pub fn fit(image: &[f32]) -> Self {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for &v in image.iter().filter(|v| v.is_finite()) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if hi > lo {
            Self {
                lo,
                gain: 255.0 / (hi - lo),
            }
        } else {
            Self { lo: 0.0, gain: 0.0 }
        }
    }

    /// The gray level of `v`.
    #[inline]
    pub fn gray(&self, v: f32) -> u8 {
        // `as` saturates and maps NaN to 0.
        ((v - self.lo) * self.gain + 0.5) as u8
    }
}

/// RGB565 of 8-bit levels (their 5, 6 and 5 top bits).
#[inline]
pub const fn rgb565(r: u8, g: u8, b: u8) -> u16 {
    (((r as u16) >> 3) << 11) | (((g as u16) >> 2) << 5) | ((b as u16) >> 3)
}

/// RGB565 of a gray level.
#[inline]
pub const fn rgb565_gray(g: u8) -> u16 {
    rgb565(g, g, g)
}

/// Why a frame could not be sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PanelError<S, P> {
    /// The SPI device failed.
    Spi(S),
    /// The D/C pin failed.
    Pin(P),
    /// Width 0, or an image that is not `width × height` pixels of
    /// `channels` values.
    BadShape {
        /// Values given.
        len: usize,
        /// Width given.
        width: usize,
        /// Values per pixel.
        channels: usize,
    },
    /// The row buffer holds fewer than `2·width` bytes.
    RowBufferTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The window runs past the panel's 16-bit address range.
    OutOfRange,
}

impl<S: fmt::Debug, P: fmt::Debug> fmt::Display for PanelError<S, P> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PanelError::Spi(e) => write!(f, "SPI write failed: {e:?}"),
            PanelError::Pin(e) => write!(f, "D/C pin failed: {e:?}"),
            PanelError::BadShape {
                len,
                width,
                channels,
            } => write!(
                f,
                "{len} values do not make rows of {width} pixels of {channels} channels"
            ),
            PanelError::RowBufferTooSmall { needed, got } => {
                write!(f, "row buffer holds {got} bytes, needs {needed}")
            }
            PanelError::OutOfRange => write!(f, "window beyond 16-bit panel addresses"),
        }
    }
}

/// An image for the panel: rows of `width` pixels of `channels` values
/// each (1 gray, 3 RGB with red first), row 0 at the top.
#[derive(Clone, Copy, Debug)]
pub struct Image<'a> {
    /// The values, row-major, channel fastest.
    pub pixels: &'a [f32],
    /// Pixels a row.
    pub width: usize,
    /// Values a pixel: 1 or 3.
    pub channels: usize,
}

impl Image<'_> {
    fn bad_shape<S, P>(self) -> PanelError<S, P> {
        PanelError::BadShape {
            len: self.pixels.len(),
            width: self.width,
            channels: self.channels,
        }
    }
}

/// A DCS panel on an SPI device and a D/C pin.
#[derive(Debug)]
pub struct DcsPanel<SPI, DC> {
    spi: SPI,
    dc: DC,
}

impl<SPI: SpiDevice, DC: OutputPin> DcsPanel<SPI, DC> {
    /// Wrap a board's SPI device and D/C pin.
    pub fn new(spi: SPI, dc: DC) -> Self {
        Self { spi, dc }
    }

    /// Give the SPI device and pin back.
    pub fn release(self) -> (SPI, DC) {
        (self.spi, self.dc)
    }

    /// Send `image` to the panel window whose top-left corner is `at`
    /// (column, row), every channel through `window` (one window keeps the
    /// colour balance of an RGB image; fit it over all values). `row` is
    /// scratch of at least `2·width` bytes.
    ///
    /// # Errors
    /// [`PanelError`]: the bus or pin failed, or the shapes do not fit
    /// (also a channel count other than 1 or 3).
    pub fn draw(
        &mut self,
        at: (u16, u16),
        image: Image<'_>,
        window: &Window,
        row: &mut [u8],
    ) -> Result<(), PanelError<SPI::Error, DC::Error>> {
        match image.channels {
            1 => self.send(at, image, row, |px| rgb565_gray(window.gray(px[0]))),
            3 => self.send(at, image, row, |px| {
                rgb565(window.gray(px[0]), window.gray(px[1]), window.gray(px[2]))
            }),
            _ => Err(image.bad_shape()),
        }
    }

    /// [`DcsPanel::draw`] with each pixel's RGB565 from `pixel`.
    fn send(
        &mut self,
        (x0, y0): (u16, u16),
        image: Image<'_>,
        row: &mut [u8],
        pixel: impl Fn(&[f32]) -> u16,
    ) -> Result<(), PanelError<SPI::Error, DC::Error>> {
        let Image {
            pixels: image,
            width,
            channels,
        } = image;
        let stride = width * channels;
        if width == 0 || image.is_empty() || image.len() % stride != 0 {
            return Err(Image {
                pixels: image,
                width,
                channels,
            }
            .bad_shape());
        }
        let height = image.len() / stride;
        let got = row.len();
        let row = row
            .get_mut(..2 * width)
            .ok_or(PanelError::RowBufferTooSmall {
                needed: 2 * width,
                got,
            })?;
        let last = |start: u16, len: usize| {
            u16::try_from(len - 1)
                .ok()
                .and_then(|l| start.checked_add(l))
                .ok_or(PanelError::OutOfRange)
        };
        let (x1, y1) = (last(x0, width)?, last(y0, height)?);
        self.command(CASET, &range_bytes(x0, x1))?;
        self.command(RASET, &range_bytes(y0, y1))?;
        self.command(RAMWR, &[])?;
        for line in image.chunks_exact(stride) {
            for (px, out) in line.chunks_exact(channels).zip(row.chunks_exact_mut(2)) {
                out.copy_from_slice(&pixel(px).to_be_bytes());
            }
            self.spi.write(row).map_err(PanelError::Spi)?;
        }
        Ok(())
    }

    /// One command byte (D/C low), then its parameters (D/C high; the pin
    /// stays high for the pixel data that follows `RAMWR`).
    fn command(&mut self, cmd: u8, params: &[u8]) -> Result<(), PanelError<SPI::Error, DC::Error>> {
        self.dc.set_low().map_err(PanelError::Pin)?;
        self.spi.write(&[cmd]).map_err(PanelError::Spi)?;
        self.dc.set_high().map_err(PanelError::Pin)?;
        if !params.is_empty() {
            self.spi.write(params).map_err(PanelError::Spi)?;
        }
        Ok(())
    }
}

fn range_bytes(first: u16, last: u16) -> [u8; 4] {
    let [a, b] = first.to_be_bytes();
    let [c, d] = last.to_be_bytes();
    [a, b, c, d]
}
