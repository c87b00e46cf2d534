//! Absurd command-line values are refused by name like in a parameter file: `--length-cv nan`
//! was taken for a fixed length, integer parameters whose arithmetic wrapped around panicked or
//! asked for terabytes.

mod common;
use common::fibercell;

#[test]
fn a_nan_length_cv_on_the_command_line_is_refused_like_in_the_file() {
    let dir = std::env::temp_dir().join(format!("fibercell-absurd-{}", std::process::id()));
    let out = fibercell()
        .args([
            "generate",
            "nonwoven",
            "--preset",
            "S",
            "--length-cv",
            "nan",
            "-o",
        ])
        .arg(dir.join("S.toml"))
        .output()
        .expect("runs");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("length cv = NaN"), "{err}");
    assert!(!dir.join("S.toml").exists());
}

/// Integer parameters whose arithmetic wrapped around are refused by name: a twill of
/// 2⁶⁴−1 over 1 passed `over + under ≤ 64` (wrapped to 0) and gave "the model is empty";
/// 2³² × 2³² knitted loops wrapped past the 10,000-loop bound and asked for 3.3 TB; a
/// geotextile layer of 2⁶⁴−1 panicked (index out of bounds) after `layer + 1` wrapped to 0.
#[test]
fn wrapping_integer_parameters_are_refused() {
    let max = usize::MAX.to_string();
    let twill = format!("twill:{max}/1");
    let wales = (1u64 << 32).to_string();
    let family = format!("0,0.001,1e-5,{max}");
    for (args, needle) in [
        (
            vec!["generate", "woven", "--pattern", &twill, "-o", "x.toml"],
            "pattern over",
        ),
        (
            vec![
                "generate",
                "knitted",
                "--wales",
                &wales,
                "--courses",
                &wales,
                "-o",
                "x.toml",
            ],
            "at most 10,000 loops",
        ),
        (
            vec![
                "generate",
                "geotextile",
                "--family",
                &family,
                "-o",
                "x.toml",
            ],
            "families[0].layer",
        ),
    ] {
        let o = fibercell().args(&args).output().expect("runs");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains(needle) && !err.contains("panicked"),
            "{args:?}: {err}"
        );
    }
}
