//! `fvr view VOLUME`: the browser viewer (web/, built by `bash
//! scripts/web.sh`) served on 127.0.0.1 at a free port with VOLUME, until
//! Ctrl-C. The page renders in WebAssembly; this server only reads volumes
//! with the project's readers and sends them in the wire format
//! ([`fvr_web::wire`]):
//!
//! - `GET /`, `/index.html`, `/fvr.js`, `/fvr_web.wasm`: the page;
//! - `GET /info`: `{"volume": NAME}`, what the page opens first;
//! - `GET /volume`: VOLUME; `GET /volume?spec=NAME`: a built-in data set
//!   or phantom (names only: the page cannot ask for a path);
//! - `POST /convert?name=FILE`: a file dropped on the page, read as its
//!   name's format says (NRRD, NIfTI, ...), or a one-line error (422).

use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use clap::Args;

use crate::args::{volume_help, InputArgs};
use crate::http::{query_value, read_request, write_response, Response};
use crate::Error;
use fvr_engine::volume::Volume;

/// The largest file the page may upload for reading (1 GiB).
const MAX_UPLOAD: u64 = 1 << 30;

#[derive(Args)]
pub(crate) struct ViewArgs {
    /// The volume the page opens first.
    #[arg(help = volume_help())]
    pub(crate) volume: String,
    /// Port on 127.0.0.1 (default: a free one).
    #[arg(long, default_value_t = 0)]
    pub(crate) port: u16,
    /// The built page (default: web/dist in the working directory or
    /// beside the repository the program was built in).
    #[arg(long, value_name = "DIR")]
    pub(crate) dist: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) input: InputArgs,
}

/// The page's three files, read once.
struct Site {
    index: Vec<u8>,
    script: Vec<u8>,
    wasm: Vec<u8>,
}

struct Served {
    site: Site,
    name: String,
    volume: Vec<u8>,
}

pub(crate) fn view(args: &ViewArgs) -> Result<(), Error> {
    // The fuzzer runs every subcommand; a server would never return.
    if cfg!(fuzzing) {
        return Err("fvr view does not serve under the fuzzer".into());
    }
    let site = find_site(args.dist.as_deref())?;
    let volume = args.input.load(&args.volume)?;
    let listener = TcpListener::bind(("127.0.0.1", args.port))
        .map_err(|e| format!("cannot listen on 127.0.0.1:{}: {e}", args.port))?;
    let addr = listener.local_addr()?;
    let served = Arc::new(Served {
        site,
        name: args.volume.clone(),
        volume: fvr_web::wire::encode(&volume),
    });
    drop(volume);
    say!(
        "fvr: serving {} at http://{addr}/ (Ctrl-C stops)",
        args.volume
    );
    for stream in listener.incoming() {
        let Ok(stream) = stream else { continue };
        let served = Arc::clone(&served);
        std::thread::spawn(move || handle(&stream, &served));
    }
    Ok(())
}

/// The built page: `--dist`, else web/dist here, else beside the
/// repository this program was built from.
fn find_site(dist: Option<&Path>) -> Result<Site, Error> {
    let candidates: Vec<PathBuf> = match dist {
        Some(d) => vec![d.to_path_buf()],
        None => vec![
            PathBuf::from("web/dist"),
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../web/dist"),
        ],
    };
    for dir in &candidates {
        let read = |f: &str| std::fs::read(dir.join(f));
        if let (Ok(index), Ok(script), Ok(wasm)) =
            (read("index.html"), read("fvr.js"), read("fvr_web.wasm"))
        {
            return Ok(Site {
                index,
                script,
                wasm,
            });
        }
    }
    Err(format!(
        "the web viewer is not built (no index.html, fvr.js and fvr_web.wasm in {}): run `bash \
         scripts/web.sh` first{}",
        candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" or "),
        if dist.is_some() {
            ""
        } else {
            ", or give --dist DIR"
        }
    )
    .into())
}

fn handle(stream: &TcpStream, served: &Served) {
    let response = match read_request(stream, MAX_UPLOAD) {
        Ok(request) => route(&request, served),
        Err(response) => response,
    };
    write_response(stream, &response);
}

fn route(request: &crate::http::Request, served: &Served) -> Response {
    let site = &served.site;
    let wire = "application/octet-stream";
    match (request.method.as_str(), request.path.as_str()) {
        ("GET", "/" | "/index.html") => {
            Response::ok("text/html; charset=utf-8", site.index.clone())
        }
        ("GET", "/fvr.js") => Response::ok("text/javascript; charset=utf-8", site.script.clone()),
        ("GET", "/fvr_web.wasm") => Response::ok("application/wasm", site.wasm.clone()),
        ("GET", "/info") => Response::ok(
            "application/json",
            serde_json::json!({ "volume": served.name })
                .to_string()
                .into_bytes(),
        ),
        ("GET", "/volume") => match query_value(&request.query, "spec") {
            None => Response::ok(wire, served.volume.clone()),
            Some(spec) => match built_in(&spec) {
                Ok(v) => Response::ok(wire, fvr_web::wire::encode(&v)),
                Err(e) => Response::error(404, &e),
            },
        },
        ("POST", "/convert") => {
            let name = query_value(&request.query, "name").unwrap_or_default();
            match convert(&name, &request.body) {
                Ok(v) => Response::ok(wire, fvr_web::wire::encode(&v)),
                Err(e) => Response::error(422, &e),
            }
        }
        (_, "/convert") => Response::error(405, "POST a file to /convert"),
        _ => Response::error(404, &format!("no such page: {}", request.path)),
    }
}

/// A data set or phantom by name; never a path.
fn built_in(spec: &str) -> Result<Volume, String> {
    if let Some(p) = fvr_host::sources::phantom_by_name(spec) {
        return p.map(|p| p.volume);
    }
    if let Some(t) = fvr_host::sources::teapot_by_name(spec) {
        return t;
    }
    fvr_host::sources::datasets::load_dataset(spec)
        .unwrap_or_else(|| Err(format!("`{spec}` is not a built-in data set or phantom")))
}

/// Read an uploaded file with the project's readers: written under its own
/// (sanitised) name in a fresh temporary directory, so that the format is
/// detected as for a file on the command line.
fn convert(name: &str, bytes: &[u8]) -> Result<Volume, String> {
    let base = Path::new(name)
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("");
    let clean: String = base
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    if clean.is_empty() || clean.starts_with('.') {
        return Err(format!("`{name}`: no file name to tell its format by"));
    }
    let dir = tempfile::tempdir().map_err(|e| format!("cannot make a temporary directory: {e}"))?;
    let path = dir.path().join(&clean);
    std::fs::write(&path, bytes).map_err(|e| format!("cannot store `{clean}`: {e}"))?;
    fvr_host::io::read_volume(&path).map_err(|e| {
        // The message names the temporary path; the user knows the file
        // by its own name.
        let m = e
            .to_string()
            .replace(&path.display().to_string(), &clean)
            .replace(&format!("{}/", dir.path().display()), "");
        if m.contains(&clean) {
            m
        } else {
            format!("{clean}: {m}")
        }
    })
}
