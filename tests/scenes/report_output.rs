//! OutputSet: all files written in order, no temp files left, bad names refused, failures
//! (target is a file, a name collides with a directory) write nothing, and what killed runs
//! leave is finished or removed.

use crate::tmp_common::TmpDir;
use std::fs;
use std::path::Path;

use texsim::report::OutputSet;

fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .expect("read_dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn sample() -> OutputSet {
    let mut o = OutputSet::new();
    o.add("hw.png", vec![1, 2, 3]);
    o.add("ref.png", vec![4; 1000]);
    o.add("metrics.json", b"{}".to_vec());
    o
}

#[test]
fn writes_all_files_without_temps() {
    let root = TmpDir::new("all");
    let dir = root.join("nested").join("out");
    let o = sample();
    let paths = o.write_to(&dir).expect("write");
    assert_eq!(
        paths,
        ["hw.png", "ref.png", "metrics.json"].map(|n| dir.join(n))
    );
    assert_eq!(fs::read(dir.join("hw.png")).expect("read"), [1, 2, 3]);
    assert_eq!(
        fs::read(dir.join("ref.png")).expect("read"),
        vec![4u8; 1000]
    );
    assert_eq!(fs::read(dir.join("metrics.json")).expect("read"), b"{}");
    assert_eq!(listing(&dir), ["hw.png", "metrics.json", "ref.png"]);
    // overwriting an existing set replaces contents, still without temp files
    let mut o2 = OutputSet::new();
    o2.add("hw.png", vec![9]);
    o2.add("hw.png", vec![7, 7]); // same name again replaces, keeps one entry
    assert_eq!(o2.len(), 1);
    o2.write_to(&dir).expect("rewrite");
    assert_eq!(fs::read(dir.join("hw.png")).expect("read"), [7, 7]);
    assert!(listing(&dir).iter().all(|n| !n.contains(".tmp")));
    assert_eq!(listing(&dir).len(), 3);
    // an empty set just makes the directory
    let empty = root.join("empty");
    assert!(OutputSet::new().write_to(&empty).expect("empty").is_empty());
    assert!(empty.is_dir());
}

#[test]
fn refuses_bad_names_and_writes_nothing() {
    let root = TmpDir::new("names");
    for bad in ["", ".", "..", "a/b.png", "../up.png", "x\\y", "a..b"] {
        let dir = root.join("out");
        let mut o = sample();
        o.add(bad, vec![0]);
        let e = o.write_to(&dir).expect_err(bad);
        assert!(e.message().contains("file name"), "{bad}: {e}");
        assert!(!dir.exists(), "{bad}: directory must not be created");
    }
    assert!(listing(&root).is_empty());
    assert!(!root.parent().expect("parent").join("up.png").exists());
}

#[test]
fn target_is_a_file() {
    let root = TmpDir::new("file");
    let target = root.join("out");
    fs::write(&target, b"keep me").expect("file");
    let e = sample().write_to(&target).expect_err("file as dir");
    assert!(e.message().contains(&target.display().to_string()), "{e}");
    assert_eq!(fs::read(&target).expect("read"), b"keep me");
    assert_eq!(listing(&root), ["out"]);
    // a path below a regular file fails too, naming the path
    let below = target.join("sub");
    let e = sample().write_to(&below).expect_err("below a file");
    assert!(e.message().contains(&below.display().to_string()), "{e}");
    assert_eq!(listing(&root), ["out"]);
}

#[test]
fn name_colliding_with_directory_writes_nothing() {
    let root = TmpDir::new("collide");
    fs::create_dir(root.join("ref.png")).expect("dir");
    let e = sample().write_to(&root).expect_err("collision");
    assert!(e.message().contains("ref.png"), "{e}");
    assert_eq!(listing(&root), ["ref.png"]);
}

#[test]
fn failed_write_removes_what_it_wrote() {
    let root = TmpDir::new("cleanup");
    let dir = root.join("out");
    sample().write_to(&dir).expect("first set");
    // The second file's name is too long for the file system: its write fails after the first
    // file was written, and the new directory goes again; the first set stays whole.
    let long = "x".repeat(300);
    let mut o = OutputSet::new();
    o.add("hw.png", vec![9]);
    o.add(&long, vec![1]);
    let e = o.write_to(&dir).expect_err("name too long");
    assert!(e.message().contains("xxxx"), "{e}");
    assert_eq!(listing(&root), ["out"]);
    assert_eq!(listing(&dir), ["hw.png", "metrics.json", "ref.png"]);
    assert_eq!(fs::read(dir.join("hw.png")).expect("read"), [1, 2, 3]);
}

/// The id of a process that has ended.
fn dead_pid() -> u32 {
    let mut c = std::process::Command::new("true").spawn().expect("spawn");
    let pid = c.id();
    c.wait().expect("wait");
    pid
}

/// What a killed run leaves is finished or removed by the next one: an incomplete new
/// directory and per-file temp files (`NAME.tmp-PID`) of earlier versions go; a complete new
/// directory whose swap was cut short is swapped in (all new), the old one removed.
#[test]
fn leftovers_of_killed_runs_are_finished_or_removed() {
    let root = TmpDir::new("killed");
    let dir = root.join("out");
    let family = ["hw.png", "ref.png", "metrics.json"];
    let mut first = sample();
    first.family(&family);
    first.write_to(&dir).expect("first");
    fs::write(dir.join("notes.txt"), b"mine").expect("foreign file");
    // Killed while writing.
    let pid = dead_pid();
    let partial = root.join(format!(".out.texsim-new-{pid}"));
    fs::create_dir(&partial).expect("partial dir");
    fs::write(partial.join("hw.png"), b"half").expect("half");
    fs::write(dir.join(format!("hw.png.tmp-{pid}")), b"half").expect("old temp");
    let mut next = OutputSet::new();
    next.add("hw.png", vec![5]);
    next.family(&family);
    next.write_to(&dir).expect("next");
    assert_eq!(listing(&root), ["out"]);
    assert_eq!(listing(&dir), ["hw.png", "notes.txt"]);
    assert_eq!(fs::read(dir.join("hw.png")).expect("read"), [5]);
    // Killed between moving the old directory aside and moving the new one in.
    let pid = dead_pid();
    let new = root.join(format!(".out.texsim-new-{pid}"));
    fs::create_dir(&new).expect("new dir");
    fs::write(new.join("hw.png"), [6]).expect("hw");
    fs::write(new.join("metrics.json"), b"{6}").expect("json");
    fs::rename(dir.join("notes.txt"), new.join("notes.txt")).expect("moved foreign file");
    fs::write(new.join(".texsim-complete"), b"").expect("marker");
    fs::rename(&dir, root.join(format!(".out.texsim-old-{pid}"))).expect("old aside");
    OutputSet::new().write_to(&dir).expect("recovering run");
    assert_eq!(listing(&root), ["out"]);
    assert_eq!(listing(&dir), ["hw.png", "metrics.json", "notes.txt"]);
    assert_eq!(fs::read(dir.join("hw.png")).expect("read"), [6]);
}

/// Outputs of an earlier run that this run did not produce are removed, but only names of the
/// set's family, only files, and only once every new file is in place.
#[test]
fn removes_stale_family_files_and_nothing_else() {
    let root = TmpDir::new("stale");
    let family = ["hw.png", "ref.png", "error.png", "hw16.png", "metrics.json"];
    let mut first = sample();
    first.add("error.png", vec![5]);
    first.add("hw16.png", vec![6]);
    first.family(&family);
    first.write_to(&root).expect("first");
    fs::write(root.join("notes.txt"), b"mine").expect("foreign file");
    fs::write(root.join("sheet.png"), b"not in the family").expect("foreign png");
    fs::create_dir(root.join("sub")).expect("dir");

    let mut second = OutputSet::new();
    second.add("hw.png", vec![8]);
    second.add("metrics.json", b"[]".to_vec());
    second.family(&family);
    let stale = second.stale_in(&root);
    assert_eq!(
        stale,
        ["ref.png", "error.png", "hw16.png"].map(|n| root.join(n))
    );
    second.write_to(&root).expect("second");
    assert_eq!(
        listing(&root),
        ["hw.png", "metrics.json", "notes.txt", "sheet.png", "sub"]
    );
    assert_eq!(fs::read(root.join("hw.png")).expect("read"), [8]);
    assert_eq!(fs::read(root.join("notes.txt")).expect("read"), b"mine");

    // A failed write removes nothing: the earlier set stays whole.
    let mut third = sample();
    third.family(&family);
    fs::write(root.join("ref.png"), b"old").expect("old ref");
    fs::write(root.join("error.png"), b"old").expect("old error");
    let mut fourth = OutputSet::new();
    fourth.add("metrics.json", vec![1]);
    fourth.add(&"y".repeat(300), vec![1]);
    fourth.family(&family);
    fourth.write_to(&root).expect_err("name too long");
    assert_eq!(fs::read(root.join("error.png")).expect("kept"), b"old");
    assert_eq!(fs::read(root.join("ref.png")).expect("kept"), b"old");
    third.write_to(&root).expect("third");
    assert!(!root.join("error.png").exists(), "error.png is stale");
    assert_eq!(
        fs::read(root.join("ref.png")).expect("read"),
        vec![4u8; 1000]
    );
    // A family name that is not a plain file name is refused before anything is written.
    let mut bad = OutputSet::new();
    bad.add("hw.png", vec![0]);
    bad.family(&["../notes.txt"]);
    assert!(bad.write_to(&root.join("never")).is_err());
    assert!(!root.join("never").exists());
}

/// The tests' scratch directories ([`TmpDir`]) live under `target/tmp`, go when their test
/// passes and stay, for inspection, when it panics.
#[test]
fn scratch_dirs_go_when_a_test_passes_and_stay_when_it_fails() {
    let passed = {
        let d = TmpDir::new("passes");
        fs::write(d.join("f"), b"x").expect("write");
        assert!(d.starts_with(env!("CARGO_TARGET_TMPDIR")));
        d.to_path_buf()
    };
    assert!(!passed.exists(), "{}", passed.display());
    let failed = std::panic::catch_unwind(|| {
        let d = TmpDir::new("fails");
        fs::write(d.join("f"), b"x").expect("write");
        std::panic::panic_any(d.to_path_buf());
    })
    .expect_err("panics");
    let failed = failed.downcast::<std::path::PathBuf>().expect("its path");
    assert!(failed.join("f").exists(), "{}", failed.display());
    fs::remove_dir_all(&*failed).expect("cleanup");
}
