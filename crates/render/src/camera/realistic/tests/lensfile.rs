//! Parsing lens files and reporting errors with file:line.

use super::super::{LensError, LensPrescription, LensSystem};
use super::{LENSES, lens, lens_record, num};

#[test]
fn reference_files_parse_like_the_reference() {
    for name in LENSES {
        let prescription = lens(name);
        let record = lens_record(name);
        let surfaces = record["surfaces"].as_array().unwrap();
        assert_eq!(prescription.surfaces.len(), surfaces.len(), "{name}");
        for (s, r) in prescription.surfaces.iter().zip(surfaces) {
            assert_eq!(s.radius, num(&r["R"]));
            assert_eq!(s.thickness, num(&r["t"]));
            // The reference already reads index 0 (the stop) as air, as we do.
            assert_eq!(s.index, num(&r["n"]));
            assert_eq!(s.aperture_diameter, num(&r["D"]));
        }
        assert_eq!(
            prescription.stop_index().unwrap() as u64,
            record["paraxial"]["stop_index"].as_u64().unwrap()
        );
        let system = LensSystem::new(&prescription).unwrap();
        assert!((system.total_track() - num(&record["paraxial"]["total_track"])).abs() < 1e-12);
    }
}

fn parse_error(text: &str) -> String {
    LensPrescription::parse(text, "test.dat")
        .unwrap_err()
        .to_string()
}

#[test]
fn malformed_rows_name_file_and_line() {
    let good = "# comment\n10 2 1.5 8\n0 1 0 6\n-10 0 1 8\n";
    assert!(LensPrescription::parse(good, "test.dat").is_ok());

    let cases = [
        (
            "# c\n10 2 1.5\n0 1 0 6\n",
            "test.dat:2:",
            "expected 4 columns",
        ),
        ("10 2 1.5 8 9\n0 1 0 6\n", "test.dat:1:", "found 5"),
        (
            "10 2 1.5 8\n0 x 0 6\n",
            "test.dat:2:",
            "thickness 'x' is not a number",
        ),
        ("10 2 1.5 8\n\n0 1 0 NaN\n", "test.dat:3:", "not finite"),
        (
            "10 2 1.5 8\n0 1 0 0\n",
            "test.dat:2:",
            "aperture diameter must be positive",
        ),
        (
            "10 2 1.5 -3\n0 1 0 6\n",
            "test.dat:1:",
            "aperture diameter must be positive",
        ),
        ("10 2 0.5 8\n0 1 0 6\n", "test.dat:1:", "refractive index"),
        (
            "10 -2 1.5 8\n0 1 0 6\n",
            "test.dat:1:",
            "thickness must not be negative",
        ),
        (
            "3 2 1.5 8\n0 1 0 6\n",
            "test.dat:1:",
            "exceeds the radius of curvature",
        ),
    ];
    for (text, location, detail) in cases {
        let message = parse_error(text);
        assert!(
            message.starts_with(location) && message.contains(detail),
            "{text:?}: {message}"
        );
    }
    assert!(parse_error("10 2 1.5 8\n-10 0 1 8\n").contains("no aperture stop"));
    assert!(parse_error("# nothing\n").contains("no lens surfaces"));
}

#[test]
fn missing_file_is_an_io_error_naming_the_path() {
    let err = LensPrescription::from_file("/nonexistent/lens.dat").unwrap_err();
    assert!(matches!(err, LensError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/lens.dat"));
}

#[test]
fn prescriptions_built_in_code_are_validated() {
    let mut p = lens("dgauss.50mm.dat");
    p.surfaces[3].index = f64::NAN;
    let message = LensSystem::new(&p).unwrap_err().to_string();
    assert!(message.contains("surface 3"), "{message}");
    let mut p = lens("dgauss.50mm.dat");
    p.surfaces[5].radius = 50.0;
    assert!(matches!(LensSystem::new(&p), Err(LensError::NoStop { .. })));
}
