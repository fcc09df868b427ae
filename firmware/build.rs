//! Build script of the firmware:
//! 1. for the thumb targets, links each program with a complete linker
//!    script of its part written to `OUT_DIR` (`link_script.rs`, which says
//!    why): the Cortex-M4F's layout is `memory.x` in the workspace root, the
//!    Cortex-M3's (target `thumbv7m-none-eabi`) `memory-m3.x`, and the
//!    Cortex-M7's (the programs named `*-m7`, on the M4F's target, so that
//!    one cargo call builds them all on one library) `memory-m7.x`; each
//!    script is that layout followed by `cortex-m-rt`'s `link.x` without its
//!    `INCLUDE memory.x`, and goes with `defmt.x`;
//! 2. runs the core **on the host** to make the flash tables: it samples the
//!    scene's phantom (`src/scene.rs`), computes its gradient magnitude
//!    `|∇f|` if a stored spectrum needs it, prepares the f16 spectra listed
//!    in `STORED`, tabulates the kernels, the kernel derivatives listed in
//!    `DERIVATIVES` and the twiddles, and writes them to
//!    `OUT_DIR` (the spectra as little-endian f16 files, the rest as Rust).
//!    For the device-preparation programs it writes u8 volumes, the filters
//!    fitted to them and their kernel tables (`make_prep_tables`);
//! 3. refuses a scene whose tables do not fit the flash of its target's
//!    layout (the root `memory.x`, or `memory-m3.x`), saying by how many
//!    bytes it is over.
//!
//! Nothing binary is kept in git: the tables are made here on every build.

use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use fvr_core::dht::fixed::{FixedSample, FixedTwiddles};
use fvr_core::dht::Twiddles;
use fvr_core::filter::{DerivativeTable, Filter, FilterKind, KernelTable};
use fvr_core::shading::gradient::{gradient_magnitude, gradient_scratch_len};
use fvr_core::spectrum::{prepare_scratch_len, Spectrum};
use fvr_core::volume::{padded_size, DenseVolume};
use half::f16;

#[allow(dead_code)]
#[path = "src/scene.rs"]
mod scene;

use scene::{StoredKind, DERIVATIVES, DIMS, OVERSAMPLE, PROGRAMS, STORED};

#[allow(dead_code)]
#[path = "src/fixed_input.rs"]
mod fixed_input;

#[allow(dead_code)]
#[path = "src/prep_volume.rs"]
mod prep_volume;

#[allow(dead_code)]
#[path = "link_script.rs"]
mod link_script;

use link_script::{read_layout, write_link_script, Part};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let manifest = PathBuf::from(env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let target = env::var("TARGET").unwrap_or_default();

    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/scene.rs");
    println!("cargo:rerun-if-changed=src/fixed_input.rs");
    println!("cargo:rerun-if-changed=link_script.rs");
    let memory = Part::of_target(&target).layout(&manifest);
    let layout = read_layout(&memory);
    if target.starts_with("thumb") {
        println!("cargo:rustc-link-arg-bins=--nmagic");
        link_scripts(&out, &manifest, &target);
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }

    let tables = make_tables(&out);
    make_fixed_tables(&out);
    make_q15_view_tables(&out);
    make_prep_tables(&out);
    check_flash_budget(&layout, &memory, &tables);
}

/// Writes the linker script of each part the programs of `target` run on
/// (`link_script::write_link_script`) and hands each program the one of
/// its part with `-T`: every program of one build links in the same cargo
/// call, with one build of the library. The programs are the `[[bin]]`
/// names of `Cargo.toml`.
fn link_scripts(out: &Path, manifest: &Path, target: &str) {
    let cargo_toml = manifest.join("Cargo.toml");
    println!("cargo:rerun-if-changed={}", cargo_toml.display());
    let manifest_text = fs::read_to_string(&cargo_toml).expect("read Cargo.toml");
    let bins = bin_names(&manifest_text);
    assert!(!bins.is_empty(), "no [[bin]] in {}", cargo_toml.display());
    let mut scripts: Vec<(Part, PathBuf)> = Vec::new();
    for bin in bins {
        let part = Part::of(target, &bin);
        let script = match scripts.iter().find(|(p, _)| *p == part) {
            Some((_, script)) => script.clone(),
            None => {
                let script = write_link_script(out, manifest, part);
                scripts.push((part, script.clone()));
                script
            }
        };
        println!("cargo:rustc-link-arg-bin={bin}=-T{}", script.display());
    }
}

/// The `name`s of the `[[bin]]` tables of a `Cargo.toml`.
fn bin_names(manifest: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut in_bin = false;
    for line in manifest.lines().map(str::trim) {
        if line.starts_with('[') {
            in_bin = line == "[[bin]]";
        } else if let Some(value) = line.strip_prefix("name").filter(|_| in_bin) {
            let value = value.trim_start().trim_start_matches('=').trim();
            names.push(value.trim_matches('"').to_string());
        }
    }
    names
}

/// The Q15 and Q31 twiddle tables of `fvr-fixed-bench`
/// (`FixedTwiddles::new` on the host, for its block side), as Rust.
fn make_fixed_tables(out: &Path) {
    fn table<S: FixedSample>(name: &str, ty: &str, src: &mut String) {
        let mut buf = vec![S::default(); FixedTwiddles::<S>::buffer_len(fixed_input::SIDE)];
        FixedTwiddles::new(&mut buf, fixed_input::SIDE).expect("fixed-point twiddles");
        let values: Vec<String> = buf.iter().map(|v| v.to_i64().to_string()).collect();
        writeln!(
            src,
            "/// `FixedTwiddles::<{ty}>::new` on the host for length {}.\n\
             pub static {name}: [{ty}; {}] = [{}];\n",
            fixed_input::SIDE,
            buf.len(),
            values.join(", ")
        )
        .unwrap();
    }
    let mut src = String::from("// @generated by firmware/build.rs: do not edit.\n\n");
    table::<i16>("TWIDDLES_Q15", "i16", &mut src);
    table::<i32>("TWIDDLES_Q31", "i32", &mut src);
    fs::write(out.join("fixed_tables.rs"), src).expect("write fixed_tables.rs");
}

/// The phantom, sampled at voxel centres (i, j, k), rounded to f32 as the
/// host's phantom sampler does.
fn phantom_voxels() -> Vec<f32> {
    let [nx, ny, nz] = DIMS;
    let mut voxels = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                voxels.push(scene::density([i as f64, j as f64, k as f64]) as f32);
            }
        }
    }
    voxels
}

/// The `StoredHeader` (src/stored.rs) of a spectrum of the phantom
/// prepared for `filter`, of side `n` and power-of-two scale `scale`, as
/// Rust source; f64 values by their bits, so they round-trip exactly.
fn header_literal(filter: &Filter, scale: f64, n: usize) -> String {
    format!(
        "StoredHeader {{\n        \
             oversample: {OVERSAMPLE},\n        \
             beta: f64::from_bits({:#018x}),\n        \
             scale: f64::from_bits({:#018x}),\n        \
             n: {n},\n        \
             dims: [{}, {}, {}],\n    \
         }}",
        filter.beta().to_bits(),
        scale.to_bits(),
        DIMS[0],
        DIMS[1],
        DIMS[2],
    )
}

/// The kb3 density spectrum of the scene's phantom in Q15 with one block
/// exponent per x-line, for the Cortex-M3's integer view
/// (`src/stored_q15.rs`): prepared in f64 by the core
/// (`Spectrum::prepare`) and rounded once (`encode_blocks`), written as
/// little-endian mantissas and exponents beside a Rust description.
fn make_q15_view_tables(out: &Path) {
    use fvr_core::num::{encode_blocks, BlockLayout, Q15};
    let voxels = phantom_voxels();
    let volume = DenseVolume::new(DIMS, &voxels).expect("phantom shape");
    let n = padded_size(DIMS, OVERSAMPLE).expect("phantom size");
    let (filter, _) =
        Filter::fit(FilterKind::Kb3, OVERSAMPLE, &volume).expect("filter design for the phantom");
    let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(n)];
    let tw = Twiddles::new(&mut tw_buf, n).expect("twiddles");
    let mut scratch = vec![0.0f64; prepare_scratch_len(n)];
    let mut data = vec![0.0f64; n * n * n];
    let spec = Spectrum::prepare(&volume, filter, &mut data, &mut scratch, &tw)
        .expect("preparing the phantom's spectrum in f64");
    let scale = spec.scale();
    let mut mantissas = vec![Q15::default(); n * n * n];
    let mut exponents = vec![0i8; n * n];
    encode_blocks(&data, n, BlockLayout::Line, &mut mantissas, &mut exponents)
        .expect("Q15 line blocks of the phantom's spectrum");
    let bytes: Vec<u8> = mantissas.iter().flat_map(|q| q.0.to_le_bytes()).collect();
    fs::write(out.join("density-kb3.q15"), &bytes).expect("write the Q15 spectrum");
    let exponent_bytes: Vec<u8> = exponents.iter().map(|e| *e as u8).collect();
    fs::write(out.join("density-kb3.q15exp"), &exponent_bytes).expect("write the exponents");
    let src = format!(
        "// @generated by firmware/build.rs from src/scene.rs: do not edit.\n\n\
         /// The phantom's kb3 density spectrum (β = {beta}), {n}³ Q15 with one\n\
         /// exponent per x-line, prepared in f64 and rounded once; scale 2^{e}.\n\
         pub static DENSITY_KB3_Q15: StoredQ15 = StoredQ15 {{\n    \
             header: {header},\n    \
             data: &DENSITY_KB3_Q15_DATA,\n    \
             exponents: &DENSITY_KB3_Q15_EXPONENTS,\n\
         }};\n\
         #[allow(long_running_const_eval)]\n\
         static DENSITY_KB3_Q15_DATA: [Q15; {cube}] =\n    \
             decode_q15(include_bytes!(concat!(env!(\"OUT_DIR\"), \"/density-kb3.q15\")));\n\
         static DENSITY_KB3_Q15_EXPONENTS: [i8; {lines}] =\n    \
             decode_i8(include_bytes!(concat!(env!(\"OUT_DIR\"), \"/density-kb3.q15exp\")));\n",
        beta = filter.beta(),
        header = header_literal(&filter, scale, n),
        e = libm::log2(scale) as i32,
        cube = n * n * n,
        lines = n * n,
    );
    fs::write(out.join("q15_tables.rs"), src).expect("write q15_tables.rs");
}

/// A table `build.rs` puts in flash.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Table {
    /// An f16 spectrum.
    Spectrum(StoredKind),
    /// A filter's kernel table (shared by the spectra of that filter).
    Kernel(FilterKind),
    /// A filter's kernel-derivative table.
    Derivative(FilterKind),
}

/// Bytes of flash one table takes.
struct Made {
    table: Table,
    bytes: usize,
}

fn make_tables(out: &Path) -> Vec<Made> {
    let voxels = phantom_voxels();
    let volume = DenseVolume::new(DIMS, &voxels).expect("phantom shape");
    let n = padded_size(DIMS, OVERSAMPLE).expect("phantom size");

    // |∇f| of the samples, in f64 and rounded to f32, as the host's
    // `fvr_engine::render::shaded::gradient_volume` makes it; only if a stored
    // spectrum needs it.
    let gradient_voxels: Option<Vec<f32>> = STORED
        .iter()
        .any(|k| matches!(k, StoredKind::GradientMagnitude(_)))
        .then(|| {
            let len = gradient_scratch_len(DIMS);
            let mut tw_buf = vec![0.0f64; Twiddles::<f64>::buffer_len(len)];
            let tw = Twiddles::new(&mut tw_buf, len).expect("twiddles");
            let mut line = vec![0.0f64; len];
            let mut g = vec![0.0f64; voxels.len()];
            gradient_magnitude(&volume, &mut g, &mut line, &tw).expect("|∇f| of the phantom");
            g.into_iter().map(|v| v as f32).collect()
        });

    let mut tw_buf = vec![0.0f32; Twiddles::<f32>::buffer_len(n)];
    Twiddles::new(&mut tw_buf, n).expect("twiddles");
    let tw = Twiddles::from_table(&tw_buf, n).expect("twiddles");
    let mut scratch = vec![0.0f32; prepare_scratch_len(n)];

    let mut src = String::new();
    writeln!(
        src,
        "// @generated by firmware/build.rs from src/scene.rs: do not edit.\n"
    )
    .unwrap();
    writeln!(
        src,
        "/// Quarter-wave sine table for transforms up to length {n}, from\n\
         /// `Twiddles::new` on the host ({} entries).\n\
         pub static TWIDDLES: [f32; {}] = {};\n",
        tw_buf.len(),
        tw_buf.len(),
        f32_array(&tw_buf)
    )
    .unwrap();

    // One filter design per filter, from the density (every spectrum of a
    // filter, density or |∇f|, is premultiplied for the same β).
    let mut filters: Vec<(FilterKind, Filter, f64)> = Vec::new();
    let mut design_for = |kind: FilterKind| -> (Filter, f64) {
        if let Some(&(_, f, d)) = filters.iter().find(|(k, _, _)| *k == kind) {
            return (f, d);
        }
        let (f, d) = Filter::fit(kind, OVERSAMPLE, &volume).expect("filter design for the phantom");
        filters.push((kind, f, d));
        (f, d)
    };

    let mut made = Vec::new();
    for kind in STORED {
        let filter_kind = kind.filter();
        let name = filter_kind.name();
        let (filter, design) = design_for(filter_kind);
        let gradient_volume;
        let (source, what) = match kind {
            StoredKind::Density(_) => (&volume, "density"),
            StoredKind::GradientMagnitude(_) => {
                let g = gradient_voxels.as_deref().expect("made above");
                gradient_volume = DenseVolume::new(DIMS, g).expect("|∇f| shape");
                (&gradient_volume, "gradient magnitude |∇f|")
            }
        };
        let mut data = vec![f16::ZERO; n * n * n];
        let spec = Spectrum::prepare(source, filter, &mut data, &mut scratch, &tw)
            .expect("preparing the phantom's spectrum");
        let scale = spec.scale();
        let bytes: Vec<u8> = data
            .iter()
            .flat_map(|h| h.to_bits().to_le_bytes())
            .collect();
        let prefix = kind.prefix();
        let file = format!("{prefix}-{name}.f16");
        fs::write(out.join(&file), &bytes).expect("write spectrum");
        let upper = format!("{}_{}", prefix.to_uppercase(), name.to_uppercase());
        let variant_path = match kind {
            StoredKind::Density(_) => "Density",
            StoredKind::GradientMagnitude(_) => "GradientMagnitude",
        };
        writeln!(
            src,
            "/// The phantom's {what} spectrum for {name} (β = {beta}, designed for\n\
             /// σ = {design:.3}), {n}³ f16, scale 2^{e}.\n\
             pub static {upper}: StoredSpectrum = StoredSpectrum {{\n    \
                 kind: StoredKind::{variant_path}(FilterKind::{variant}),\n    \
                 header: {header},\n    \
                 data: &{upper}_DATA,\n    \
                 kernel: &KERNEL_{kupper},\n\
             }};\n\
             #[allow(long_running_const_eval)]\n\
             static {upper}_DATA: [f16; {cube}] =\n    \
                 decode_f16(include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{file}\")));\n",
            beta = filter.beta(),
            variant = variant(name),
            header = header_literal(&filter, scale, n),
            e = libm::log2(scale) as i32,
            cube = n * n * n,
            kupper = name.to_uppercase(),
        )
        .unwrap();
        made.push(Made {
            table: Table::Spectrum(kind),
            bytes: bytes.len(),
        });
        if !made.iter().any(|m| m.table == Table::Kernel(filter_kind)) {
            let kernel = KernelTable::<f32>::new(filter);
            writeln!(
                src,
                "/// The {name} kernel tabulated by `KernelTable::new` on the host.\n\
                 static KERNEL_{}: [f32; {}] = {};\n",
                name.to_uppercase(),
                kernel.values().len(),
                f32_array(kernel.values()),
            )
            .unwrap();
            made.push(Made {
                table: Table::Kernel(filter_kind),
                bytes: 4 * kernel.values().len(),
            });
        }
    }
    for filter_kind in DERIVATIVES {
        let name = filter_kind.name();
        let (filter, _) = design_for(filter_kind);
        let table = DerivativeTable::<f32>::new(filter).expect("a kernel with a derivative");
        let upper = name.to_uppercase();
        writeln!(
            src,
            "/// The {name} kernel derivative tabulated by `DerivativeTable::new`\n\
             /// on the host (β = {beta}).\n\
             pub static DERIVATIVE_{upper}: StoredDerivative = StoredDerivative {{\n    \
                 kind: FilterKind::{variant},\n    \
                 oversample: {OVERSAMPLE},\n    \
                 beta: f64::from_bits({beta_bits:#018x}),\n    \
                 values: &DERIVATIVE_{upper}_VALUES,\n\
             }};\n\
             static DERIVATIVE_{upper}_VALUES: [f32; {len}] = {arr};\n",
            beta = filter.beta(),
            variant = variant(name),
            beta_bits = filter.beta().to_bits(),
            len = table.values().len(),
            arr = f32_array(table.values()),
        )
        .unwrap();
        made.push(Made {
            table: Table::Derivative(filter_kind),
            bytes: 4 * table.values().len(),
        });
    }
    fs::write(out.join("tables.rs"), src).expect("write tables.rs");
    made
}

fn variant(name: &str) -> String {
    let mut c = name.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

fn f32_array(values: &[f32]) -> String {
    let mut s = String::from("[");
    for (i, v) in values.iter().enumerate() {
        if i % 6 == 0 {
            s.push_str("\n    ");
        }
        write!(s, "f32::from_bits({:#010x}), ", v.to_bits()).unwrap();
    }
    s.push_str("\n]");
    s
}

/// The scene's tables per program against the FLASH region of `layout`:
/// fail the build, saying by how much, if a program's tables alone do not
/// fit. (The linker then checks tables plus code: "region `FLASH'
/// overflowed by N bytes".)
fn check_flash_budget(layout: &str, path: &Path, made: &[Made]) {
    let flash = region_length(layout, "FLASH").unwrap_or_else(|| {
        panic!(
            "no `FLASH : ORIGIN = …, LENGTH = …` line in {}",
            path.display()
        )
    });
    for (program, frames) in PROGRAMS {
        let mut tables: Vec<Table> = Vec::new();
        for f in frames.iter() {
            let (density, gradient) = f.spectra();
            let mut needs = vec![Table::Spectrum(density), Table::Kernel(f.filter)];
            needs.extend(gradient.map(Table::Spectrum));
            if f.shading.needs_kernel_derivative() {
                needs.push(Table::Derivative(f.filter));
            }
            for table in needs {
                if !made.iter().any(|m| m.table == table) {
                    panic!(
                        "frame {} of {program} needs {table:?}, which src/scene.rs does not \
                         list in STORED or DERIVATIVES",
                        f.name
                    );
                }
                if !tables.contains(&table) {
                    tables.push(table);
                }
            }
        }
        let bytes: usize = made
            .iter()
            .filter(|m| tables.contains(&m.table))
            .map(|m| m.bytes)
            .sum();
        if bytes > flash {
            panic!(
                "the scene of {program} does not fit: its spectra and kernel tables take \
                 {bytes} bytes of flash, FLASH in {} holds {flash} bytes: over by {} bytes",
                path.display(),
                bytes - flash
            );
        }
    }
}

/// `LENGTH` of a `MEMORY` region, e.g. `FLASH : ORIGIN = 0x0, LENGTH = 2M`.
fn region_length(layout: &str, region: &str) -> Option<usize> {
    let line = layout
        .lines()
        .map(str::trim)
        .find(|l| l.starts_with(region) && l.contains("LENGTH"))?;
    let value = line.split("LENGTH").nth(1)?.trim_start_matches([' ', '=']);
    let value = value.trim().trim_end_matches(',');
    let (digits, unit) = match value.chars().last()? {
        'K' | 'k' => (&value[..value.len() - 1], 1024),
        'M' | 'm' => (&value[..value.len() - 1], 1024 * 1024),
        _ => (value, 1),
    };
    let number = if let Some(hex) = digits.strip_prefix("0x") {
        usize::from_str_radix(hex, 16).ok()?
    } else {
        digits.parse().ok()?
    };
    Some(number * unit)
}

/// The inputs of the device-preparation programs (`fvr-prepare`,
/// `fvr-prepare-m7`): for each side, the u8 volume
/// (`prep_volume::voxel_u8`) as a file `prep-volume-<side>.u8`, and, as
/// Rust, the kb3 filter `Filter::fit` designs for it and its kernel table.
fn make_prep_tables(out: &Path) {
    println!("cargo:rerun-if-changed=src/prep_volume.rs");
    let mut src = String::from("// @generated by firmware/build.rs: do not edit.\n\n");
    for side in [prep_volume::M4F_SIDE, prep_volume::M7_SIDE] {
        let mut voxels = Vec::with_capacity(side * side * side);
        for k in 0..side {
            for j in 0..side {
                for i in 0..side {
                    voxels.push(prep_volume::voxel_u8(side, [i, j, k]));
                }
            }
        }
        let file = format!("prep-volume-{side}.u8");
        fs::write(out.join(&file), &voxels).expect("write the u8 volume");
        let volume = DenseVolume::new([side; 3], &voxels).expect("volume shape");
        let (filter, _) =
            Filter::fit(FilterKind::Kb3, 1, &volume).expect("filter design for the u8 volume");
        let kernel = KernelTable::<f32>::new(filter);
        writeln!(
            src,
            "/// The {side}³ u8 volume, the kb3 filter `Filter::fit` designs for it\n\
             /// on the host (β = {beta}) and its kernel table.\n\
             pub static PREP_{side}: PrepInput = PrepInput {{\n    \
                 side: {side},\n    \
                 kind: FilterKind::Kb3,\n    \
                 oversample: 1,\n    \
                 beta: f64::from_bits({bits:#018x}),\n    \
                 voxels: include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{file}\")),\n    \
                 kernel: &PREP_KERNEL_{side},\n\
             }};\n\
             static PREP_KERNEL_{side}: [f32; {len}] = {arr};\n",
            beta = filter.beta(),
            bits = filter.beta().to_bits(),
            len = kernel.values().len(),
            arr = f32_array(kernel.values()),
        )
        .unwrap();
    }
    fs::write(out.join("prep_tables.rs"), src).expect("write prep_tables.rs");
}
