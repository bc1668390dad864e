//! The scenario loader: built-ins, overrides, typed errors naming the key or line, no panic on
//! arbitrary input (property tests), reproducible generation.

use datasets::DatasetError;
use grainlaw::scenarios::common::build::{column, column_width};
use grainlaw::scenarios::janssen::config::JanssenConfig;
use grainlaw::scenarios::registry::{config_of, from_text, load, SCENARIOS};
use grainlaw::scenarios::stick_slip::config::StickSlipConfig;
use proptest::prelude::*;

#[test]
fn every_builtin_loads_and_has_a_seed() {
    for b in SCENARIOS.iter() {
        let l = load(b.name(), &[]).unwrap_or_else(|e| panic!("{}: {e}", b.name()));
        assert_eq!(l.config.kind(), b.name());
        assert_eq!(l.source, format!("builtin:{}", b.name()));
        assert!(
            b.builtin_toml().contains("seed ="),
            "{} has no seed key",
            b.name()
        );
        // The seed can be changed like any key.
        let l = load(b.name(), &["seed=42".into()]).unwrap();
        assert_eq!(l.config.seed(), 42);
    }
}

#[test]
fn overrides_reach_the_typed_config() {
    let l = load(
        "janssen",
        &[
            "grains=2000".into(),
            "grain.radius_mean=2e-3".into(),
            "friction.grain_wall=0.4".into(),
        ],
    )
    .unwrap();
    let c: JanssenConfig = config_of(&l).unwrap();
    assert_eq!(c.grains, 2000);
    assert_eq!(c.grain.radius_mean, 2e-3);
    assert_eq!(c.friction.grain_wall, 0.4);
    assert!(l.effective_toml.contains("grains = 2000"));
    // The effective TOML loads back to the same configuration.
    let again = from_text("j", "effective", &l.effective_toml, &[]).unwrap();
    assert_eq!(config_of::<JanssenConfig>(&again).unwrap(), c);
}

/// The built-in Janssen column averages its measurement over 4 steps; a scenario file written
/// before `analysis.measure_steps` existed (without the key) keeps the one measured step it was
/// run with, so an archived run runs again the same.
#[test]
fn janssen_measurement_window_of_builtin_and_of_older_files() {
    let builtin = load("janssen", &[]).unwrap();
    let c: JanssenConfig = config_of(&builtin).unwrap();
    assert_eq!(c.analysis.measure_steps, 4);
    let older: String = builtin
        .effective_toml
        .lines()
        .filter(|l| !l.trim_start().starts_with("measure_steps"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert!(!older.contains("measure_steps"));
    let c: JanssenConfig = config_of(&from_text("older", "older", &older, &[]).unwrap()).unwrap();
    assert_eq!(c.analysis.measure_steps, 1);
}

#[test]
fn errors_name_the_key_or_line() {
    let t = grainlaw::scenarios::registry::get("rolling")
        .unwrap()
        .builtin_toml();
    let e = from_text("r", "f.toml", &format!("{t}\nextra = 1\n"), &[]).unwrap_err();
    assert!(
        matches!(&e, DatasetError::UnknownKey { key, .. } if key == "extra"),
        "{e}"
    );
    let jt = grainlaw::scenarios::registry::get("janssen")
        .unwrap()
        .builtin_toml()
        .replace("radius_spread", "radius_sprad");
    let e = from_text("j", "f.toml", &jt, &[]).unwrap_err();
    assert!(e.to_string().contains("grain.radius_sprad"), "{e}");
    let e = from_text(
        "r",
        "f.toml",
        &t.replace("radius = 0.01", "radius = \"big\""),
        &[],
    )
    .unwrap_err();
    assert!(e.to_string().contains("radius"), "{e}");
    let e = from_text(
        "r",
        "f.toml",
        "scenario = \"rolling\"\nseed = 1\nslope_deg = = 3\n",
        &[],
    )
    .unwrap_err();
    assert!(matches!(e, DatasetError::Syntax { line: 3, .. }), "{e}");
    let e = from_text(
        "r",
        "f.toml",
        &t.replace("radius = 0.01", "radius = -0.01"),
        &[],
    )
    .unwrap_err();
    assert!(
        matches!(&e, DatasetError::Invalid { key, .. } if key == "radius"),
        "{e}"
    );
    let e = from_text(
        "r",
        "f.toml",
        &t.replace("scenario = \"rolling\"", "scenario = \"flying\""),
        &[],
    )
    .unwrap_err();
    assert!(e.to_string().contains("flying"), "{e}");
    let e = load("nothing-like-this", &[]).unwrap_err();
    assert!(matches!(e, DatasetError::UnknownScenario { .. }));
    // The message really is one line.
    assert!(!e.to_string().contains('\n'));
}

/// The janssen box is about ten mean diameters wide for 350 grains, and a column of the same
/// seed is generated identically (a different seed differs).
#[test]
fn janssen_geometry_and_reproducible_generation() {
    let c: JanssenConfig = config_of(&load("janssen", &[]).unwrap()).unwrap();
    let w = column_width(&c.grain, c.grains, c.column_aspect);
    let diameters = w / (2.0 * c.grain.radius_mean);
    assert!((9.0..11.0).contains(&diameters), "{diameters}");
    let a = column(&c.grain, c.grains, w, &c.friction, 7, 1e-3).unwrap();
    let b = column(&c.grain, c.grains, w, &c.friction, 7, 1e-3).unwrap();
    let d = column(&c.grain, c.grains, w, &c.friction, 8, 1e-3).unwrap();
    let pos = |x: &grainlaw::scenarios::common::build::ColumnWorld| -> Vec<u64> {
        x.world
            .bodies
            .iter()
            .flat_map(|b| {
                [
                    b.position.x.to_bits(),
                    b.position.y.to_bits(),
                    b.radius.to_bits(),
                ]
            })
            .collect()
    };
    assert_eq!(pos(&a), pos(&b));
    assert_ne!(pos(&a), pos(&d));
    // Radii within the configured range, grains between the walls.
    for g in a
        .world
        .bodies
        .iter()
        .filter(|b| b.kind == dem::BodyKind::Grain)
    {
        assert!(g.radius >= c.grain.radius_min() && g.radius <= c.grain.radius_max());
        assert!(g.position.x - g.radius >= 0.0 && g.position.x + g.radius <= w);
    }
}

/// A grain dropped on the floor comes to rest; the phase counts its steps.
#[test]
fn run_until_rest_stops_at_rest() {
    let c: StickSlipConfig = config_of(&load("stick-slip", &["grains=3".into()]).unwrap()).unwrap();
    let mut col = column(&c.grain, 3, 0.02, &c.cases.walls_and_grains, 1, 1e-3).unwrap();
    let stats = grainlaw::scenarios::phases::run_until_rest(
        &mut col.world,
        &grainlaw::scenarios::phases::RunUntilRest {
            min_time: 0.0,
            max_time: 2.0,
            rest_energy: 1e-8,
        },
        |_, _| true,
    )
    .unwrap();
    assert!(stats.at_rest);
    assert!(stats.steps < 2000 && stats.steps >= grainlaw::scenarios::phases::REST_STEPS as u64);
    assert!(
        grainlaw::scenarios::phases::translational_energy(&col.world)
            < 1e-8 * grainlaw::scenarios::phases::energy_scale(&col.world)
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    /// Arbitrary text never panics the loader.
    #[test]
    fn loader_never_panics_on_arbitrary_text(text in ".{0,400}") {
        let _ = from_text("x", "fuzz.toml", &text, &[]);
    }

    /// Built-in scenarios with one line deleted or one value replaced by an arbitrary token load
    /// or fail with an error, never a panic.
    #[test]
    fn loader_never_panics_on_mutated_builtins(which in 0usize..6, line in 0usize..60, token in "[-a-z0-9.\\[\\]\"=]{0,12}") {
        let t = SCENARIOS[which].builtin_toml();
        let mut lines: Vec<String> = t.lines().map(String::from).collect();
        let k = line % lines.len();
        if let Some((key, _)) = lines[k].split_once('=') {
            lines[k] = format!("{key}= {token}");
        } else {
            lines.remove(k);
        }
        let _ = from_text("x", "fuzz.toml", &lines.join("\n"), &[]);
    }

    /// Arbitrary --set arguments never panic.
    #[test]
    fn overrides_never_panic(key in "[a-z_.]{0,20}", value in ".{0,16}") {
        let _ = load("janssen", &[format!("{key}={value}")]);
    }
}
