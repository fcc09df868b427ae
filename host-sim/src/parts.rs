//! The parts `fvr prepare --for` budgets a prepared spectrum against: their
//! flash and RAM (the firmware's memory layouts: `memory.x` for the M4F,
//! `firmware/memory-m3.x` and `firmware/memory-m7.x`), and
//! what a `.fvrs` image and one view at full size need of each.

use fvr_core::filter::KernelTable;
use fvr_core::fvrs::Part;
use fvr_core::image::{aux_len, grid_len};

/// Flash and RAM of a part, in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Memory {
    /// Flash (code and `const` data).
    pub flash: u64,
    /// RAM (data, stack, view buffers).
    pub ram: u64,
    /// The memory layout it comes from.
    pub layout: &'static str,
}

/// The memory of `part`; `None` for the host, which is not budgeted here
/// (its memory limit is `--max-memory`'s).
pub fn memory(part: Part) -> Option<Memory> {
    const K: u64 = 1024;
    match part {
        Part::Host => None,
        Part::M4f => Some(Memory {
            flash: 2048 * K,
            ram: 512 * K,
            layout: "memory.x",
        }),
        Part::M3 => Some(Memory {
            flash: 4096 * K,
            ram: 4096 * K,
            layout: "firmware/memory-m3.x",
        }),
        Part::M7 => Some(Memory {
            flash: 2048 * K,
            ram: 1024 * K,
            layout: "firmware/memory-m7.x",
        }),
    }
}

/// Flash kept for the program itself: the C API's library and a small
/// application. The C example (`firmware/c-example`, every filter and both
/// precisions linked) takes 306,426 bytes without its image
/// (`arm-none-eabi-size`, `bash scripts/capi.sh`; `docs/firmware.md`).
pub const CODE_FLASH: u64 = 320 * 1024;
/// RAM kept for the stack and the application's own data.
pub const STACK_RAM: u64 = 16 * 1024;

/// Where the image lies at run time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placement {
    /// In flash, read in place (`--emit c`, `--emit fvrs`).
    Flash,
    /// Loaded into RAM at run time (`--emit bin`).
    Ram,
}

/// What a device needs to render full-size views of an image of
/// `image_len` bytes and side `n`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Need {
    /// Flash: the program and, in flash, the image.
    pub flash: u64,
    /// RAM: the view's f32 buffers (slice grid, scratch, an `n × n`
    /// image), the kernel table copied out of the image, the stack, and,
    /// loaded into RAM, the image.
    pub ram: u64,
}

/// The need of an image ([`Need`]).
pub fn need(image_len: u64, n: usize, placement: Placement) -> Need {
    let floats = (grid_len(n) + aux_len(n) + n * n) as u64;
    let view = 4 * floats + std::mem::size_of::<KernelTable<f32>>() as u64;
    let (flash, ram) = match placement {
        Placement::Flash => (image_len, 0),
        Placement::Ram => (0, image_len),
    };
    Need {
        flash: CODE_FLASH + flash,
        ram: STACK_RAM + view + ram,
    }
}

/// `Ok` if `need` fits `part`, else one line naming the part, the memory,
/// the need and the limit.
pub fn check(part: Part, need: Need) -> Result<(), String> {
    let Some(m) = memory(part) else {
        return Ok(());
    };
    for (what, need, limit) in [("flash", need.flash, m.flash), ("RAM", need.ram, m.ram)] {
        if need > limit {
            return Err(format!(
                "does not fit the {} ({}): needs {} of {what} ({}), the part has {} ({}); over by {}",
                part.name(),
                m.layout,
                bytes(need),
                need,
                bytes(limit),
                limit,
                bytes(need - limit)
            ));
        }
    }
    Ok(())
}

/// `n` bytes in KiB or MiB, one decimal.
pub fn bytes(n: u64) -> String {
    if n >= 1 << 20 {
        format!("{:.1} MiB", n as f64 / (1u64 << 20) as f64)
    } else {
        format!("{:.1} KiB", n as f64 / 1024.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The figures above are the firmware's memory layouts'.
    #[test]
    fn figures_match_the_memory_layouts() {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../");
        for part in [Part::M4f, Part::M3, Part::M7] {
            let m = memory(part).unwrap();
            let text = std::fs::read_to_string(format!("{root}{}", m.layout)).unwrap();
            let length = |region: &str| -> u64 {
                let line = text
                    .lines()
                    .find(|l| l.trim_start().starts_with(region))
                    .unwrap();
                let v = line.split("LENGTH").nth(1).unwrap();
                let v = v.trim_start_matches([' ', '=']).trim();
                let (num, unit) = v.split_at(v.len() - 1);
                num.trim().parse::<u64>().unwrap()
                    * match unit {
                        "K" => 1024,
                        "M" => 1 << 20,
                        _ => panic!("{v}"),
                    }
            };
            assert_eq!(length("FLASH"), m.flash, "{part:?}");
            assert_eq!(length("RAM"), m.ram, "{part:?}");
        }
    }

    #[test]
    fn over_budget_names_part_need_and_limit() {
        let big = need(4 << 20, 128, Placement::Flash);
        let e = check(Part::M4f, big).unwrap_err();
        assert!(
            e.contains("m4f") && e.contains("flash") && e.contains("2.0 MiB"),
            "{e}"
        );
        assert!(check(Part::Host, big).is_ok());
        // The M3's 4 MiB hold a 3 MiB image beside the program, not 4 MiB.
        assert!(check(Part::M3, big).unwrap_err().contains("m3"));
        assert!(check(Part::M3, need(3 << 20, 128, Placement::Flash)).is_ok());
        let ram = need(600 << 10, 64, Placement::Ram);
        assert!(check(Part::M4f, ram).unwrap_err().contains("RAM"));
        assert!(check(Part::M7, ram).is_ok());
    }
}
