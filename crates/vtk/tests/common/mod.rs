//! Running Python checks with meshio, the independent reader of the VTU
//! files (`.ci/run` installs the Debian package python3-meshio).

use std::process::Command;

/// A Python with meshio: `python3`, or the system's `/usr/bin/python3`
/// where `python3` is another installation.
fn python_with_meshio() -> String {
    for p in ["python3", "/usr/bin/python3"] {
        let ok = Command::new(p)
            .args(["-c", "import meshio"])
            .output()
            .is_ok_and(|o| o.status.success());
        if ok {
            return p.to_string();
        }
    }
    panic!("no Python with meshio: install it (Debian: apt-get install python3-meshio; pip install meshio)");
}

/// Runs the Python `script`, which prints `ok` when its checks pass, and
/// prints what it printed.
pub fn check_with_python(script: &str) {
    let o = Command::new(python_with_meshio())
        .args(["-c", script])
        .output()
        .unwrap();
    // what the script measured (`--nocapture` shows it)
    println!("{}", String::from_utf8_lossy(&o.stdout));
    assert!(
        o.status.success() && String::from_utf8_lossy(&o.stdout).contains("ok"),
        "meshio check failed:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}
