//! `radiant slurm` end to end: jobs its tasks would refuse are refused before anything
//! is written, values cannot add lines or words to the job scripts, and a failed run
//! leaves no folders behind.

use std::path::Path;
use std::process::Command;

mod common;
use common::*;

fn failure(dir: &Path, args: &[&str]) -> String {
    let out = radiant_in(dir, args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !out.status.success(),
        "radiant {} succeeded: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn jobs_every_task_would_refuse_are_refused_up_front() {
    let d = temp_dir("refuse");
    let job = |extra: &[&'static str]| {
        [
            &[
                "slurm",
                "cornell-box",
                "-o",
                "out.exr",
                "--resolution",
                "8x6",
            ][..],
            extra,
        ]
        .concat()
    };
    // More bands of rows than the image has rows.
    let e = failure(&d, &job(&["--parts", "7"]));
    assert!(e.contains("--parts 7") && e.contains("6 rows"), "{e}");
    // 100 spp make two blocks of 64: three parts by samples cannot share them.
    let e = failure(
        &d,
        &job(&["--parts", "3", "--part-by", "samples", "--spp", "100"]),
    );
    assert!(e.contains("2 block(s)"), "{e}");
    // SPPM's iterations are not split by samples.
    let e = failure(
        &d,
        &job(&[
            "--parts",
            "2",
            "--part-by",
            "samples",
            "--integrator",
            "sppm",
        ]),
    );
    assert!(e.contains("sppm"), "{e}");
    let e = failure(&d, &job(&["--parts", "2", "--integrator", "bogus"]));
    assert!(e.contains("unknown integrator"), "{e}");
    assert_eq!(entries(&d), Vec::<String>::new(), "nothing is written");
    // What the tasks take is written.
    let out = radiant_in(&d, &job(&["--parts", "6"]));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        entries(&d.join("out.slurm")),
        ["logs", "merge.sbatch", "parts", "render.sbatch"]
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn values_cannot_add_lines_or_words_to_the_scripts() {
    let d = temp_dir("inject");
    let base = ["slurm", "--parts", "2", "--resolution", "8x6"];
    let run = |extra: &[&'static str]| [&base[..], extra].concat();
    let e = failure(
        &d,
        &run(&["-o", "out.exr", "--partition", "p\ntouch INJECTED"]),
    );
    assert!(e.contains("control characters"), "{e}");
    let e = failure(
        &d,
        &run(&["-o", "out.exr", "--time", "1:00\ntouch INJECTED"]),
    );
    assert!(e.contains("not a Slurm time"), "{e}");
    let e = failure(&d, &run(&["-o", "out.exr", "--time", "1:2:3:4"]));
    assert!(e.contains("not a Slurm time"), "{e}");
    let e = failure(&d, &run(&["-o", "out.exr", "--dir", "jobs\nrm -rf x"]));
    assert!(e.contains("control characters"), "{e}");
    assert_eq!(entries(&d), Vec::<String>::new(), "nothing is written");

    // Blanks, quotes and `#` stay inside one word of each script.
    std::fs::create_dir(d.join("a b")).unwrap();
    let out = radiant_in(
        &d,
        &run(&[
            "-o",
            "a b/it's #1.exr",
            "--partition",
            "gpu \"x\"",
            "--time",
            "1-02:03",
        ]),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let job = d.join("a b/it's #1.slurm");
    let render = std::fs::read_to_string(job.join("render.sbatch")).unwrap();
    let merge = std::fs::read_to_string(job.join("merge.sbatch")).unwrap();
    let dir = job.display().to_string();
    assert!(
        render.contains("#SBATCH --partition=\"gpu \\\"x\\\"\"\n"),
        "{render}"
    );
    assert!(render.contains("#SBATCH --time=1-02:03\n"), "{render}");
    assert!(
        render.contains(&format!(
            "#SBATCH --output=\"{dir}/logs/render-%A_%a.log\"\n"
        )),
        "{render}"
    );
    let output = d.join("a b/it's #1.exr").display().to_string();
    assert!(
        merge.contains(&format!("-o '{}'\n", output.replace('\'', r"'\''"))),
        "{merge}"
    );
    // The shell reads the scripts as written (no stray quote ends a word early).
    for script in ["render.sbatch", "merge.sbatch"] {
        let status = Command::new("bash")
            .arg("-n")
            .arg(job.join(script))
            .status()
            .expect("bash runs");
        assert!(status.success(), "{script}");
    }
    std::fs::remove_dir_all(&d).ok();
}

/// A small job, to which the test adds where its scripts go.
const CLEANUP_JOB: [&str; 7] = [
    "slurm",
    "--parts",
    "2",
    "--resolution",
    "8x6",
    "-o",
    "out.exr",
];

#[test]
fn a_failed_run_removes_the_folders_it_made() {
    let d = temp_dir("cleanup");
    // The job script cannot be written (a folder holds its name), as on a full disk.
    let job = d.join("job");
    std::fs::create_dir_all(job.join("render.sbatch")).unwrap();
    let e = failure(&d, &[&CLEANUP_JOB[..], &["--dir", "job"]].concat());
    assert!(e.contains("render.sbatch"), "{e}");
    assert_eq!(
        entries(&job),
        ["render.sbatch"],
        "parts and logs are removed"
    );
    // A script written before the failure goes too.
    std::fs::remove_dir(job.join("render.sbatch")).unwrap();
    std::fs::create_dir(job.join("merge.sbatch")).unwrap();
    let e = failure(&d, &[&CLEANUP_JOB[..], &["--dir", "job"]].concat());
    assert!(e.contains("merge.sbatch"), "{e}");
    assert_eq!(entries(&job), ["merge.sbatch"]);
    // With no sbatch to submit them, the folders the run made, to the top, are removed.
    let out = radiant()
        .current_dir(&d)
        .env("PATH", &job)
        .args(CLEANUP_JOB)
        .args(["--dir", "new/deeper", "--submit"])
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("sbatch"),
        "{stderr}"
    );
    assert!(!d.join("new").exists(), "{:?}", entries(&d));
    std::fs::remove_dir_all(&d).ok();
}
