//! The display sink on the host: a capture SPI device and D/C pin record
//! what `DcsPanel` sends, and the bytes are checked against the MIPI DCS
//! protocol and against the image.

use std::convert::Infallible;

use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiDevice};
use fvr_firmware::capture::{decode_frame, ByteSink, CaptureBus, CaptureError, DecodeError};
use fvr_firmware::display::{
    rgb565, rgb565_gray, DcsPanel, Image, PanelError, Window, CASET, RAMWR, RASET,
};

#[derive(Default)]
struct Memory(Vec<u8>);

impl ByteSink for Memory {
    type Error = Infallible;
    fn put(&mut self, bytes: &[u8]) -> Result<(), Infallible> {
        self.0.extend_from_slice(bytes);
        Ok(())
    }
}

/// Split a recording into (D/C level, bytes) records.
fn records(rec: &[u8]) -> Vec<(u8, Vec<u8>)> {
    let mut out = Vec::new();
    let mut at = 0;
    while at < rec.len() {
        let len = u32::from_le_bytes(rec[at + 1..at + 5].try_into().unwrap()) as usize;
        out.push((rec[at], rec[at + 5..at + 5 + len].to_vec()));
        at += 5 + len;
    }
    out
}

/// The panel's view of `pixels`: rows of `width` pixels of `channels`
/// values.
fn picture(pixels: &[f32], width: usize, channels: usize) -> Image<'_> {
    Image {
        pixels,
        width,
        channels,
    }
}

/// What `DcsPanel` sends to draw `picture` at `origin` through `window`,
/// with a row buffer of `row_len` bytes, as recorded by a capture bus.
fn recording(origin: (u16, u16), picture: Image<'_>, window: &Window, row_len: usize) -> Vec<u8> {
    let bus = CaptureBus::new(Memory::default());
    let mut panel = DcsPanel::new(bus.spi(), bus.dc());
    let mut row = vec![0u8; row_len];
    panel.draw(origin, picture, window, &mut row).unwrap();
    let _ = panel.release();
    bus.into_inner().0
}

#[test]
fn a_frame_is_caset_raset_ramwr_then_rgb565_rows_with_dc_levels() {
    // 3 × 2 image at (10, 300): values 0..5, window 0..5 → gray 0, 51, …, 255.
    let image: Vec<f32> = (0..6).map(|v| v as f32).collect();
    let window = Window::fit(&image);
    assert_eq!(
        window,
        Window {
            lo: 0.0,
            gain: 51.0
        }
    );
    let rec = records(&recording((10, 300), picture(&image, 3, 1), &window, 6));
    let px = |g: u8| rgb565_gray(g).to_be_bytes();
    let row0: Vec<u8> = [0u8, 51, 102].iter().flat_map(|&g| px(g)).collect();
    let row1: Vec<u8> = [153u8, 204, 255].iter().flat_map(|&g| px(g)).collect();
    assert_eq!(
        rec,
        vec![
            (0, vec![CASET]),
            (1, vec![0, 10, 0, 12]),
            (0, vec![RASET]),
            (1, vec![0x01, 0x2C, 0x01, 0x2D]),
            (0, vec![RAMWR]),
            (1, row0),
            (1, row1),
        ]
    );
    // RGB565 of gray: 5/6/5 top bits, white is all ones.
    assert_eq!(rgb565_gray(255), 0xFFFF);
    assert_eq!(rgb565_gray(0), 0);
    assert_eq!(rgb565_gray(0b1000_0100), 0b1000_0100_0011_0000);
}

#[test]
fn a_recording_decodes_to_the_window_and_the_quantized_image() {
    let (w, h) = (64, 48);
    let image: Vec<f32> = (0..w * h)
        .map(|i| ((i % w) as f32 * 0.37 - (i / w) as f32 * 0.11).sin() * 3.0 + 1.0)
        .collect();
    let window = Window::fit(&image);
    let rec = recording((5, 7), picture(&image, w, 1), &window, 2 * w);
    let mut pixels = vec![0u16; w * h];
    let frame = decode_frame(&rec, &mut pixels).unwrap();
    assert_eq!(frame.columns, (5, 5 + w as u16 - 1));
    assert_eq!(frame.rows, (7, 7 + h as u16 - 1));
    assert_eq!(frame.pixels, w * h);
    let expected: Vec<u16> = image.iter().map(|&v| rgb565_gray(window.gray(v))).collect();
    assert_eq!(pixels, expected);
    // The window spans the image: its minimum is black, its maximum white.
    assert!(pixels.contains(&0) && pixels.contains(&0xFFFF));
}

#[test]
fn an_rgb_frame_sends_one_rgb565_pixel_per_three_values_through_one_window() {
    // 2 × 2 RGB image: one window over all 12 values, 0..=11 → gain 255/11.
    let image: Vec<f32> = (0..12).map(|v| v as f32).collect();
    let window = Window::fit(&image);
    let rec = recording((3, 4), picture(&image, 2, 3), &window, 4);
    let mut pixels = vec![0u16; 4];
    let frame = decode_frame(&rec, &mut pixels).unwrap();
    assert_eq!((frame.columns, frame.rows), ((3, 4), (4, 5)));
    let expected: Vec<u16> = image
        .chunks_exact(3)
        .map(|p| rgb565(window.gray(p[0]), window.gray(p[1]), window.gray(p[2])))
        .collect();
    assert_eq!(pixels, expected);
    // The first pixel is (0, 23, 46) in 8 bits; the last is (209, 232, 255).
    assert_eq!(pixels[0], (23 >> 2) << 5 | (46 >> 3));
    assert_eq!(pixels[3], (209 >> 3) << 11 | (232 >> 2) << 5 | (255 >> 3));
    // Channels land in their own bits: pure red, green and blue.
    assert_eq!(rgb565(255, 0, 0), 0xF800);
    assert_eq!(rgb565(0, 255, 0), 0x07E0);
    assert_eq!(rgb565(0, 0, 255), 0x001F);
}

#[test]
fn window_saturates_and_handles_constant_and_non_finite_images() {
    let w = Window::fit(&[1.0, f32::NAN, 3.0, f32::INFINITY]);
    assert_eq!(
        w,
        Window {
            lo: 1.0,
            gain: 127.5
        }
    );
    assert_eq!(w.gray(-10.0), 0);
    assert_eq!(w.gray(10.0), 255);
    assert_eq!(w.gray(f32::NAN), 0);
    assert_eq!(w.gray(2.0), 128);
    let flat = Window::fit(&[2.0; 4]);
    assert_eq!(flat.gray(2.0), 0);
    assert_eq!(Window::fit(&[f32::NAN]).gray(1.0), 0);
}

#[test]
fn bad_shapes_are_refused_before_anything_is_sent() {
    let bus = CaptureBus::new(Memory::default());
    let mut panel = DcsPanel::new(bus.spi(), bus.dc());
    let image = [0.0f32; 6];
    let w = Window::fit(&image);
    let mut row = [0u8; 4];
    assert_eq!(
        panel.draw((0, 0), picture(&image, 4, 1), &w, &mut [0u8; 8]),
        Err(PanelError::BadShape {
            len: 6,
            width: 4,
            channels: 1
        })
    );
    assert_eq!(
        panel.draw((0, 0), picture(&image, 0, 1), &w, &mut row),
        Err(PanelError::BadShape {
            len: 6,
            width: 0,
            channels: 1
        })
    );
    assert_eq!(
        panel.draw((0, 0), picture(&image, 3, 1), &w, &mut row),
        Err(PanelError::RowBufferTooSmall { needed: 6, got: 4 })
    );
    assert_eq!(
        panel.draw((u16::MAX - 1, 0), picture(&image, 3, 1), &w, &mut [0u8; 6]),
        Err(PanelError::OutOfRange)
    );
    // Six values are two RGB pixels: not rows of 4 pixels, nor of 3.
    let err = panel.draw((0, 0), picture(&image, 3, 3), &w, &mut [0u8; 6]);
    assert_eq!(
        err,
        Err(PanelError::BadShape {
            len: 6,
            width: 3,
            channels: 3
        })
    );
    assert_eq!(
        err.unwrap_err().to_string(),
        "6 values do not make rows of 3 pixels of 3 channels"
    );
    let _ = panel.release();
    assert!(bus.into_inner().0.is_empty());
}

/// An SPI device whose every write fails, as a broken bus would.
struct Broken;

impl ErrorType for Broken {
    type Error = ErrorKind;
}

impl SpiDevice for Broken {
    fn transaction(&mut self, _: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        Err(ErrorKind::ModeFault)
    }
}

#[test]
fn bus_errors_reach_the_caller() {
    let bus = CaptureBus::new(Memory::default());
    let mut panel = DcsPanel::new(Broken, bus.dc());
    let image = [1.0f32, 2.0];
    let err = panel
        .draw(
            (0, 0),
            picture(&image, 2, 1),
            &Window::fit(&image),
            &mut [0u8; 4],
        )
        .unwrap_err();
    assert_eq!(err, PanelError::Spi(ErrorKind::ModeFault));
    assert_eq!(err.to_string(), "SPI write failed: ModeFault");
    // The capture device refuses reads: a display sink only writes.
    let mut spi = bus.spi();
    let mut buf = [0u8; 2];
    assert_eq!(spi.read(&mut buf), Err(CaptureError::ReadUnsupported));
}

#[test]
fn malformed_recordings_are_refused() {
    let frame = |records: &[(u8, &[u8])]| {
        let mut rec = Vec::new();
        for (dc, bytes) in records {
            rec.push(*dc);
            rec.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
            rec.extend_from_slice(bytes);
        }
        rec
    };
    let mut px = [0u16; 4];
    // A 2 × 2 window (columns and rows 0 ..= 1), then `pixels` written.
    let window_2x2 = |pixels: &[u8]| {
        frame(&[
            (0, &[CASET]),
            (1, &[0, 0, 0, 1]),
            (0, &[RASET]),
            (1, &[0, 0, 0, 1]),
            (0, &[RAMWR]),
            (1, pixels),
        ])
    };
    let good = window_2x2(&[1, 2, 3, 4, 5, 6, 7, 8]);
    assert!(decode_frame(&good, &mut px).is_ok());
    assert_eq!(px, [0x0102, 0x0304, 0x0506, 0x0708]);
    assert_eq!(
        decode_frame(&good[..good.len() - 1], &mut px),
        Err(DecodeError::Truncated { offset: 36 })
    );
    let short = window_2x2(&[1, 2, 3, 4, 5, 6]);
    assert_eq!(
        decode_frame(&short, &mut px),
        Err(DecodeError::PixelCount {
            bytes: 6,
            expected: 4
        })
    );
    assert_eq!(
        decode_frame(&frame(&[(0, &[0x11])]), &mut px),
        Err(DecodeError::UnknownCommand { command: 0x11 })
    );
    assert_eq!(
        decode_frame(&frame(&[(1, &[0])]), &mut px),
        Err(DecodeError::DataWithoutCommand)
    );
    assert_eq!(
        decode_frame(&frame(&[(2, &[CASET])]), &mut px),
        Err(DecodeError::BadLevel { offset: 0 })
    );
    assert_eq!(
        decode_frame(
            &frame(&[(0, &[CASET]), (1, &[0, 2, 0, 1]), (0, &[RAMWR])]),
            &mut px
        ),
        Err(DecodeError::BadRange { command: CASET })
    );
    assert_eq!(
        decode_frame(&frame(&[(0, &[RAMWR])]), &mut px),
        Err(DecodeError::Incomplete)
    );
}
