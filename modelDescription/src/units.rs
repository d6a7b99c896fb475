//! SI units known to the declarations, with their base-unit exponents and
//! display units (FMI 2.0 `UnitDefinitions`).

/// A display unit: `value_display = factor * value + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DisplayUnit {
    pub name: &'static str,
    pub factor: f64,
}

/// A unit and its SI base-unit exponents.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    pub name: &'static str,
    pub kg: i32,
    pub m: i32,
    pub s: i32,
    pub rad: i32,
    /// Ampere exponent.
    pub a: i32,
    /// `BaseUnit` factor: value in SI base units = factor × value (1 for SI units).
    pub factor: f64,
    pub display_units: &'static [DisplayUnit],
}

const DEG: DisplayUnit = DisplayUnit {
    name: "deg",
    factor: 57.295_779_513_082_32,
};
const DEG_PER_S: DisplayUnit = DisplayUnit {
    name: "deg/s",
    factor: 57.295_779_513_082_32,
};

const fn unit(name: &'static str, kg: i32, m: i32, s: i32, rad: i32) -> Unit {
    Unit {
        name,
        kg,
        m,
        s,
        rad,
        a: 0,
        factor: 1.0,
        display_units: &[],
    }
}

/// Every unit a declaration may use.
pub const UNITS: &[Unit] = &[
    unit("m", 0, 1, 0, 0),
    unit("m/s", 0, 1, -1, 0),
    unit("m/s2", 0, 1, -2, 0),
    unit("m2", 0, 2, 0, 0),
    unit("s", 0, 0, 1, 0),
    unit("1/s", 0, 0, -1, 0),
    unit("kg", 1, 0, 0, 0),
    unit("kg.m2", 1, 2, 0, 0),
    unit("kg/m3", 1, -3, 0, 0),
    unit("N", 1, 1, -2, 0),
    unit("N/s", 1, 1, -3, 0),
    unit("rad/s2", 0, 0, -2, 1),
    unit("N/m", 1, 0, -2, 0),
    unit("N.s/m", 1, 0, -1, 0),
    Unit {
        name: "rad",
        kg: 0,
        m: 0,
        s: 0,
        rad: 1,
        a: 0,
        factor: 1.0,
        display_units: &[DEG],
    },
    Unit {
        name: "rad/s",
        kg: 0,
        m: 0,
        s: -1,
        rad: 1,
        a: 0,
        factor: 1.0,
        display_units: &[DEG_PER_S],
    },
    // Pressure: the pitot's differential pressure.
    unit("Pa", 1, -1, -2, 0),
    // Magnetic flux density, CGS: 1 Gauss = 1e-4 T = 1e-4 kg·A⁻¹·s⁻² (`factor` 1e-4 to SI).
    Unit {
        name: "Gauss",
        kg: 1,
        m: 0,
        s: -2,
        rad: 0,
        a: -1,
        factor: 1e-4,
        display_units: &[],
    },
];

/// Look a unit up by name.
pub fn find(name: &str) -> Option<&'static Unit> {
    UNITS.iter().find(|u| u.name == name)
}
