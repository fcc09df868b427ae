//! `fvr view`: the viewer's server speaks HTTP on 127.0.0.1 only, sends the
//! page's files, the volume in the wire format and built-in volumes by name
//! (never a path), reads uploaded files with the project's readers (one
//! line when they are bad), and refuses to start without a built page.

mod common;
use common::{assert_error, fvr_line, fvr_ok, temp_dir};

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};

/// `fvr view` on a made-up page in `dir`, and the address it printed.
struct Server {
    child: Child,
    addr: String,
}

impl Server {
    fn start(volume: &str, dist: &std::path::Path) -> Self {
        let mut child = Command::new(env!("CARGO_BIN_EXE_fvr"))
            .args(["--quiet", "view", volume, "--dist"])
            .arg(dist)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut line = String::new();
        BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        let addr = line
            .split("http://")
            .nth(1)
            .and_then(|rest| rest.split('/').next())
            .unwrap_or_else(|| panic!("no address in {line:?}"))
            .to_string();
        assert!(addr.starts_with("127.0.0.1:"), "{line}");
        Self { child, addr }
    }

    /// Status line and body of one request.
    fn request(&self, method: &str, target: &str, body: &[u8]) -> (u16, Vec<u8>) {
        let mut s = TcpStream::connect(&self.addr).unwrap();
        write!(
            s,
            "{method} {target} HTTP/1.1\r\nHost: {}\r\nContent-Length: {}\r\n\r\n",
            self.addr,
            body.len()
        )
        .unwrap();
        s.write_all(body).unwrap();
        let mut reply = Vec::new();
        s.read_to_end(&mut reply).unwrap();
        let split = reply.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
        let head = String::from_utf8_lossy(&reply[..split]).to_string();
        let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
        (status, reply[split + 4..].to_vec())
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn fake_dist(name: &str) -> std::path::PathBuf {
    let dir = temp_dir(name);
    for (f, text) in [
        ("index.html", "<p>page</p>"),
        ("fvr.js", "// js"),
        ("fvr_web.wasm", "wasm"),
    ] {
        std::fs::write(dir.join(f), text).unwrap();
    }
    dir
}

#[test]
fn serves_the_page_and_volumes() {
    let dist = fake_dist("view-serve");
    let server = Server::start("gaussians@16", &dist);
    assert_eq!(
        server.request("GET", "/", b""),
        (200, b"<p>page</p>".to_vec())
    );
    assert_eq!(server.request("GET", "/fvr.js", b"").1, b"// js");
    let (status, info) = server.request("GET", "/info", b"");
    assert_eq!(status, 200);
    assert!(String::from_utf8_lossy(&info).contains("\"gaussians@16\""));
    let (status, wire) = server.request("GET", "/volume", b"");
    assert_eq!(status, 200);
    let volume = fvr_web::wire::decode(&wire).unwrap();
    assert_eq!(volume.dims, [16; 3]);
    let (status, wire) = server.request("GET", "/volume?spec=sphere%4012", b"");
    assert_eq!(status, 200);
    assert_eq!(fvr_web::wire::decode(&wire).unwrap().dims, [12; 3]);
    // Names only: a path is not a built-in volume.
    let path = dist.join("index.html");
    let target = format!("/volume?spec={}", path.display());
    let (status, body) = server.request("GET", &target, b"");
    assert_eq!(status, 404);
    assert!(String::from_utf8_lossy(&body).contains("not a built-in"));
    assert_eq!(server.request("GET", "/nothing", b"").0, 404);
}

#[test]
fn uploads_are_read_by_the_projects_readers() {
    let dist = fake_dist("view-upload");
    let server = Server::start("sphere@8", &dist);
    // A NRRD file as `fvr convert` writes it comes back as its volume.
    let dir = temp_dir("view-upload-files");
    fvr_ok("--quiet convert gaussians@10 --out g.nrrd", &dir);
    let bytes = std::fs::read(dir.join("g.nrrd")).unwrap();
    let (status, wire) = server.request("POST", "/convert?name=g.nrrd", &bytes);
    assert_eq!(status, 200, "{}", String::from_utf8_lossy(&wire));
    assert_eq!(fvr_web::wire::decode(&wire).unwrap().dims, [10; 3]);
    // Truncated and foreign files: one line naming the file, status 422.
    let half = &bytes[..bytes.len() / 2];
    for (name, body, needle) in [
        ("cut.nrrd", half, "truncated"),
        (
            "notes.nii",
            &b"not a volume at all, just some text"[..],
            "notes.nii",
        ),
    ] {
        let (status, message) = server.request("POST", &format!("/convert?name={name}"), body);
        let message = String::from_utf8_lossy(&message);
        assert_eq!(status, 422, "{name}: {message}");
        assert!(
            message.contains(needle) && message.contains(name),
            "{message}"
        );
        assert!(
            !message.contains('\n') && !message.contains("/tmp"),
            "{message}"
        );
    }
    assert_eq!(server.request("GET", "/convert", b"").0, 405);
}

#[test]
fn an_unbuilt_page_is_one_line() {
    let dir = temp_dir("view-unbuilt");
    let out = fvr_line("view brainsmall --dist no-such-dist", &dir);
    assert_error(&out, &["not built", "scripts/web.sh"]);
}
