//! conventions — the axis systems tyre data come in, and their mapping into
//! ISO-W (TYDEX W), the one system used inside tyrekit.
//!
//! # Axis systems
//! * **ISO-W / TYDEX W** (ISO 8855, TYDEX 1.3; MF-Tyre, MFeval, Adams Tire):
//!   origin at the contact point, x forward along the intersection of wheel
//!   plane and road, **y left, z up**. Slip angle α positive when the contact
//!   centre moves towards +y (so a positive α gives a *negative* Fy, which is
//!   why PKY1 is negative in ISO `.tir` files); inclination γ positive for a
//!   positive rotation about x (wheel top towards −y), which with the usual
//!   negative PKY6 gives negative camber thrust — the sign the real
//!   `TyreData.csv` shows (IA = +4° at α ≈ 0: Fy ≈ −300 N at 1.6 kN).
//!   κ positive when driving. Fz positive pressing the tyre on the road.
//! * **SAE** (SAE J670; the FSAE TTC / Calspan TIRF exports): x forward,
//!   **y right, z down**. It is ISO rotated 180° about x, so every vector's y
//!   and z components change sign (Fy, Fz) and so does every rotation about y
//!   or z (My, Mz, slip angle), while x components and rotations about x
//!   (Fx, Mx, inclination) are kept. The loaded tyre therefore shows FZ < 0.
//! * **adapted ISO** (Pacejka, *Tyre and Vehicle Dynamics*, 3rd ed., §1.2 and
//!   Fig. 1.4): ISO axes with the slip angle sign reversed, so that Fy and α
//!   have the same sign. Only α flips.
//! * **TYDEX C** (ISO-C): origin at the wheel centre, x parallel to the road
//!   in the wheel plane, y along the spin axis (tilted by γ), z = x × y.
//!   Forces are rotated by −γ about x into W, and moments are additionally
//!   transferred from the wheel centre to the contact point using the loaded
//!   radius Rl (so recordings in C need an Rl channel).
//!
//! Sources checked: Adams Tire, "About Axis Systems and Sign Conventions"
//! (ISO-W definitions of α, γ, κ, Fz up); Project Chrono's Pacejka tyre
//! (SAE→ISO: Fy, My, Mz negated, Fx, Mx kept); SAE J670 axis definitions.
//! The real flat-belt data set `TyreData.csv` (ISO-W, TTC-like) has IA of
//! +2°/+4° (TTC exports IA positive) and negative camber thrust, consistent
//! with the inclination being kept SAE→ISO.
//!
//! Must never: apply a sign without it being in [`SIGN_TABLE`] (one table,
//! used both by the conversion and by the README).

/// Axis system of a recording.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum AxisSystem {
    /// SAE J670 (FSAE TTC / Calspan): y right, z down.
    Sae,
    /// ISO 8855 = TYDEX W = ISO-W: y left, z up, contact-point origin.
    Iso,
    /// Pacejka's adapted ISO: ISO with α reversed.
    AdaptedIso,
    /// TYDEX W (identical to ISO-W).
    TydexW,
    /// TYDEX C: wheel-centre, wheel-fixed axes (tilted by γ).
    TydexC,
}

impl AxisSystem {
    /// Parse a name: `sae`, `iso`, `iso-w`, `adapted-iso`, `tydex-w`, `tydex-c`, `iso-c`.
    pub fn parse(s: &str) -> Option<Self> {
        match s
            .trim()
            .to_ascii_lowercase()
            .replace(['_', ' '], "-")
            .as_str()
        {
            "sae" | "sae-j670" => Some(Self::Sae),
            "iso" | "iso-w" | "iso8855" => Some(Self::Iso),
            "adapted-iso" | "adaptediso" => Some(Self::AdaptedIso),
            "tydex-w" | "w" | "tydexw" => Some(Self::TydexW),
            "tydex-c" | "iso-c" | "c" | "tydexc" => Some(Self::TydexC),
            _ => None,
        }
    }
    /// Name as accepted by [`AxisSystem::parse`].
    pub fn name(self) -> &'static str {
        match self {
            Self::Sae => "sae",
            Self::Iso => "iso-w",
            Self::AdaptedIso => "adapted-iso",
            Self::TydexW => "tydex-w",
            Self::TydexC => "tydex-c",
        }
    }
}

/// Quantities whose sign depends on the axis system.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// Longitudinal force Fx (N), along x; in ISO-W positive forward (driving).
    Fx,
    /// Lateral force Fy (N), along y (ISO-W: positive to the left; SAE: to the right).
    Fy,
    /// Normal force Fz (N), along z; ISO-W (z up): positive when the road
    /// presses on the tyre, SAE (z down): negative.
    Fz,
    /// Overturning moment Mx (N·m), about x.
    Mx,
    /// Rolling-resistance moment My (N·m), about y.
    My,
    /// Self-aligning moment Mz (N·m), about z.
    Mz,
    /// Slip angle α (rad), a rotation about z; ISO-W: positive when the contact
    /// centre moves towards +y (so Fy < 0), adapted ISO: same sign as Fy.
    SlipAngle,
    /// Inclination angle γ (rad), a rotation about x; positive for a positive
    /// rotation about x (ISO-W: wheel top towards −y, to the right).
    Inclination,
    /// Longitudinal slip ratio κ (–), positive when driving in every system.
    SlipRatio,
    /// Turn slip φt (1/m): the wheel's yaw rate over its contact-centre speed,
    /// a path curvature (Pacejka: φt = −ψ̇/Vc), signed about z.
    TurnSlip,
    /// Forward speed Vx (m/s) of the wheel centre, along x.
    Speed,
    /// Wheel spin rate Ω (rad/s), stored as the forward rolling speed
    /// (positive rolling forward) whatever the axes.
    WheelSpin,
}

/// One row of the sign table: the factor that maps a value recorded in each
/// system onto ISO-W (`iso = factor * recorded`).
#[derive(Clone, Copy, Debug)]
pub struct SignRow {
    /// The quantity this row maps.
    pub quantity: Quantity,
    /// Label for tables.
    pub label: &'static str,
    /// Factor (±1) from SAE J670 (FSAE TTC / Calspan) to ISO-W.
    pub sae: f64,
    /// Factor (±1) from ISO-W to ISO-W: always +1.
    pub iso: f64,
    /// Factor (±1) from Pacejka's adapted ISO to ISO-W (−1 for α only).
    pub adapted_iso: f64,
    /// Factor (±1) from TYDEX W to ISO-W: always +1 (the same axes).
    pub tydex_w: f64,
    /// TYDEX C: factor before the γ rotation / moment transfer.
    pub tydex_c: f64,
    /// Why (one line, for the README).
    pub why: &'static str,
}

/// THE sign table (recorded → ISO-W factor). Used by [`to_iso_factor`] and
/// printed by [`sign_table_markdown`].
pub const SIGN_TABLE: [SignRow; 12] = [
    SignRow {
        quantity: Quantity::Fx,
        label: "Fx",
        sae: 1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "x axis common to all",
    },
    SignRow {
        quantity: Quantity::Fy,
        label: "Fy",
        sae: -1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "SAE y points right",
    },
    SignRow {
        quantity: Quantity::Fz,
        label: "Fz",
        sae: -1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "SAE z points down (loaded tyre shows FZ < 0)",
    },
    SignRow {
        quantity: Quantity::Mx,
        label: "Mx",
        sae: 1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "rotation about the common x axis; C: transferred to the contact point",
    },
    SignRow {
        quantity: Quantity::My,
        label: "My",
        sae: -1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "rotation about y, which SAE reverses",
    },
    SignRow {
        quantity: Quantity::Mz,
        label: "Mz",
        sae: -1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "rotation about z, which SAE reverses",
    },
    SignRow {
        quantity: Quantity::SlipAngle,
        label: "slip angle α",
        sae: -1.0,
        iso: 1.0,
        adapted_iso: -1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "rotation about z; adapted ISO defines α with Fy",
    },
    SignRow {
        quantity: Quantity::Inclination,
        label: "inclination γ",
        sae: 1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "rotation about the common x axis",
    },
    SignRow {
        quantity: Quantity::SlipRatio,
        label: "slip ratio κ",
        sae: 1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "positive driving in all",
    },
    SignRow {
        quantity: Quantity::TurnSlip,
        label: "turn slip φt",
        sae: -1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "rotation rate about z",
    },
    SignRow {
        quantity: Quantity::Speed,
        label: "speed Vx",
        sae: 1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "along x",
    },
    SignRow {
        quantity: Quantity::WheelSpin,
        label: "wheel spin Ω",
        sae: 1.0,
        iso: 1.0,
        adapted_iso: 1.0,
        tydex_w: 1.0,
        tydex_c: 1.0,
        why: "reported as forward rolling speed (positive rolling forward)",
    },
];

/// Factor mapping a recorded value of `q` in `sys` onto ISO-W.
pub fn to_iso_factor(sys: AxisSystem, q: Quantity) -> f64 {
    let row = SIGN_TABLE.iter().find(|r| r.quantity == q);
    match row {
        Some(r) => match sys {
            AxisSystem::Sae => r.sae,
            AxisSystem::Iso => r.iso,
            AxisSystem::AdaptedIso => r.adapted_iso,
            AxisSystem::TydexW => r.tydex_w,
            AxisSystem::TydexC => r.tydex_c,
        },
        None => 1.0,
    }
}

/// The sign table as a Markdown table (for the README and `data summary`).
pub fn sign_table_markdown() -> String {
    let mut s = String::from(
        "| quantity | SAE (TTC) | ISO-W / TYDEX W | adapted ISO | TYDEX C | why |\n|---|---|---|---|---|---|\n",
    );
    let f = |x: f64| if x < 0.0 { "−1 (flip)" } else { "+1" };
    for r in SIGN_TABLE.iter() {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {}{} | {} |\n",
            r.label,
            f(r.sae),
            f(r.iso),
            f(r.adapted_iso),
            f(r.tydex_c),
            match r.quantity {
                Quantity::Fy | Quantity::Fz | Quantity::Mx | Quantity::My | Quantity::Mz =>
                    ", rotated by γ (+ moment transfer)",
                _ => "",
            },
            r.why
        ));
    }
    s
}

/// A force/moment/kinematics record in some axis system (SI units).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AxisSample {
    /// Longitudinal force Fx (N), along the sample system's x axis.
    pub fx: f64,
    /// Lateral force Fy (N), along the sample system's y axis.
    pub fy: f64,
    /// Normal force Fz (N), along the sample system's z axis (ISO-W: positive
    /// on a loaded tyre; SAE: negative).
    pub fz: f64,
    /// Overturning moment Mx (N·m), about x.
    pub mx: f64,
    /// Rolling-resistance moment My (N·m), about y.
    pub my: f64,
    /// Self-aligning moment Mz (N·m), about z.
    pub mz: f64,
    /// Slip angle α (rad), with the sample system's sign.
    pub alpha: f64,
    /// Inclination angle γ (rad), with the sample system's sign.
    pub gamma: f64,
    /// Longitudinal slip ratio κ (–), positive when driving.
    pub kappa: f64,
    /// Turn slip φt (1/m), with the sample system's sign.
    pub phit: f64,
    /// Loaded radius (m), needed for TYDEX C only.
    pub rl: f64,
}

/// The sign factors of one axis system, looked up once (for per-row use).
#[derive(Clone, Copy, Debug)]
pub struct ToIso {
    sys: AxisSystem,
    k: [f64; 10],
}

impl ToIso {
    /// Factors of `sys` from [`SIGN_TABLE`].
    pub fn new(sys: AxisSystem) -> ToIso {
        use Quantity as Q;
        let q = [
            Q::Fx,
            Q::Fy,
            Q::Fz,
            Q::Mx,
            Q::My,
            Q::Mz,
            Q::SlipAngle,
            Q::Inclination,
            Q::SlipRatio,
            Q::TurnSlip,
        ];
        ToIso {
            sys,
            k: q.map(|q| to_iso_factor(sys, q)),
        }
    }

    /// Map one record into ISO-W (see [`to_iso`]).
    #[inline]
    pub fn apply(&self, r: &AxisSample) -> AxisSample {
        let k = &self.k;
        let mut o = AxisSample {
            fx: k[0] * r.fx,
            fy: k[1] * r.fy,
            fz: k[2] * r.fz,
            mx: k[3] * r.mx,
            my: k[4] * r.my,
            mz: k[5] * r.mz,
            alpha: k[6] * r.alpha,
            gamma: k[7] * r.gamma,
            kappa: k[8] * r.kappa,
            phit: k[9] * r.phit,
            rl: r.rl,
        };
        if self.sys == AxisSystem::TydexC {
            let (s, c) = o.gamma.sin_cos();
            // C axes = W axes rotated by +γ about x: v_W = R_x(γ) v_C.
            let rot = |y: f64, z: f64| (c * y - s * z, s * y + c * z);
            let (fy, fz) = rot(o.fy, o.fz);
            let (my, mz) = rot(o.my, o.mz);
            o.fy = fy;
            o.fz = fz;
            o.my = my;
            o.mz = mz;
            // M_contact = M_centre + r × F, r = centre − contact = Rl (0, −sin γ, cos γ).
            let (ry, rz) = (-r.rl * s, r.rl * c);
            o.mx += ry * o.fz - rz * o.fy;
            o.my += rz * o.fx;
            o.mz += -ry * o.fx;
        }
        o
    }
}

/// Map one record from `sys` into ISO-W. For TYDEX C the forces and moments
/// are rotated from the wheel-fixed frame (tilted by γ about x) into W, and
/// moments are transferred from the wheel centre to the contact point, the
/// centre lying at `Rl·(0, −sin γ, cos γ)` from the contact point in W.
pub fn to_iso(sys: AxisSystem, r: &AxisSample) -> AxisSample {
    ToIso::new(sys).apply(r)
}

/// Inverse of [`to_iso`] (used by the writers and the rig).
pub fn from_iso(sys: AxisSystem, w: &AxisSample) -> AxisSample {
    use Quantity as Q;
    let mut v = *w;
    if sys == AxisSystem::TydexC {
        let (s, c) = w.gamma.sin_cos();
        let (ry, rz) = (-w.rl * s, w.rl * c);
        v.mx -= ry * w.fz - rz * w.fy;
        v.my -= rz * w.fx;
        v.mz -= -ry * w.fx;
        let rot = |y: f64, z: f64| (c * y + s * z, -s * y + c * z);
        let (fy, fz) = rot(v.fy, v.fz);
        let (my, mz) = rot(v.my, v.mz);
        v.fy = fy;
        v.fz = fz;
        v.my = my;
        v.mz = mz;
    }
    // Every factor is ±1, so it is its own inverse.
    let k = |q| to_iso_factor(sys, q);
    AxisSample {
        fx: k(Q::Fx) * v.fx,
        fy: k(Q::Fy) * v.fy,
        fz: k(Q::Fz) * v.fz,
        mx: k(Q::Mx) * v.mx,
        my: k(Q::My) * v.my,
        mz: k(Q::Mz) * v.mz,
        alpha: k(Q::SlipAngle) * v.alpha,
        gamma: k(Q::Inclination) * v.gamma,
        kappa: k(Q::SlipRatio) * v.kappa,
        phit: k(Q::TurnSlip) * v.phit,
        rl: v.rl,
    }
}
