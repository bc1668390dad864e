//! The built-in scenarios: TOML files under `datasets/scenarios/`, embedded in the binary.

/// A built-in scenario: its name, a one-line description and its full TOML text.
#[derive(Debug, Clone, Copy)]
pub struct Builtin {
    /// Name given on the command line.
    pub name: &'static str,
    /// One-line description.
    pub description: &'static str,
    /// Full TOML text (every key).
    pub toml: &'static str,
}

/// Every built-in scenario, the default (`janssen`) first.
pub const BUILTINS: [Builtin; 9] = [
    Builtin {
        name: "janssen",
        description: "350 grains deposited in a column, relaxed, released: wall stress vs depth, Janssen fit (Fig. 7)",
        toml: include_str!("../scenarios/janssen.toml"),
    },
    Builtin {
        name: "rolling",
        description: "one disk rolling down a slope: exact mean stress with inertia (eq. 13-14)",
        toml: include_str!("../scenarios/rolling.toml"),
    },
    Builtin {
        name: "arrangements",
        description: "rectangular, triangular, cannonball stacks in a box: load on the walls (Fig. 5)",
        toml: include_str!("../scenarios/arrangements.toml"),
    },
    Builtin {
        name: "stick-slip",
        description: "bottom wall pushed up under a deposit, three friction cases (Fig. 6)",
        toml: include_str!("../scenarios/stick-slip.toml"),
    },
    Builtin {
        name: "inclined-flow",
        description: "480 grains flowing down a rough 26° slope: inertia-ratio map (Fig. 4), velocity profile",
        toml: include_str!("../scenarios/inclined-flow.toml"),
    },
    Builtin {
        name: "shear-cell",
        description: "plane shear at imposed pressure over several inertial numbers: mu(I), phi(I), wall law",
        toml: include_str!("../scenarios/shear-cell.toml"),
    },
    Builtin {
        name: "simple-shear",
        description: "Lees-Edwards shear of a biperiodic cell at imposed normal stress over several inertial numbers: mu(I), phi(I)",
        toml: include_str!("../scenarios/simple-shear.toml"),
    },
    Builtin {
        name: "biaxial",
        description: "biaxial compression of a biperiodic cell at constant lateral stress over several confining pressures: peak and critical friction, dilatancy, Mohr-Coulomb",
        toml: include_str!("../scenarios/biaxial.toml"),
    },
    Builtin {
        name: "column-collapse",
        description: "a 2D column of about 2500 grains (a = 6.26) collapsing onto a rough floor: front x_f(t), profiles, runout, against contact dynamics",
        toml: include_str!("../scenarios/column-collapse.toml"),
    },
];

/// The built-in scenario of that name.
pub fn builtin(name: &str) -> Option<&'static Builtin> {
    BUILTINS.iter().find(|b| b.name == name)
}

/// Built-in names, comma separated.
pub fn builtin_names() -> String {
    BUILTINS
        .iter()
        .map(|b| b.name)
        .collect::<Vec<_>>()
        .join(", ")
}
