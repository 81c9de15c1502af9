//! keys — the one table of numeric `.tir` keys tyrekit understands: name,
//! usual section, physical dimension (for `[UNITS]` conversion) and default.
//!
//! Everything else (the parameter struct [`MfParams`], name lookup, the
//! writer's section layout, the list of defaulted keys) is derived from this
//! table by the `tir_keys!` macro, so a key is declared exactly once.
//!
//! Defaults: where MFeval 4.0's reader (and TNO's template file) supplies a
//! value for a missing key, that value is used, so that files which omit keys
//! evaluate as they do in the reference; every other coefficient defaults to 0
//! and every scaling factor (`L*`) to 1.
//!
//! Must never: hold state, allocate on lookup by index, or contain a key twice
//! (a unit test checks the last).

/// Physical dimension of a key's value. `[UNITS]` converts these to SI on read
/// and the writer always writes SI.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dim {
    /// Dimensionless (all Magic Formula coefficients and scaling factors).
    One,
    /// Length (m).
    Length,
    /// Force (N).
    Force,
    /// Angle (rad).
    Angle,
    /// Mass (kg).
    Mass,
    /// Time (s).
    Time,
    /// Pressure (Pa).
    Pressure,
    /// Speed (m/s).
    Speed,
    /// Linear stiffness (N/m).
    Stiffness,
    /// Linear damping (N s/m).
    Damping,
    /// Rotational stiffness (N m/rad).
    TorsionStiffness,
    /// Moment of inertia (kg m²).
    Inertia,
    /// Acceleration (m/s²).
    Acceleration,
    /// Frequency (Hz = 1/s).
    Frequency,
}

/// One entry of the key table.
#[derive(Clone, Copy, Debug)]
pub struct KeyDef {
    /// Key as written in the file (upper case).
    pub name: &'static str,
    /// Section it normally lives in (without brackets).
    pub section: &'static str,
    /// Physical dimension, for `[UNITS]` conversion.
    pub dim: Dim,
    /// Value used when the file does not give one.
    pub default: f64,
}

macro_rules! unit_of {
    ($x:tt) => {
        ()
    };
}

macro_rules! tir_keys {
    ($( [$section:literal] $( $field:ident $name:literal $dim:ident $default:expr ; )* )*) => {
        /// Number of numeric keys in the table.
        pub const N_KEYS: usize = <[()]>::len(&[$($(unit_of!($field)),*),*]);

        /// The key table, in writer order (sections in order of first use).
        pub const KEYS: [KeyDef; N_KEYS] = [
            $( $( KeyDef { name: $name, section: $section, dim: Dim::$dim, default: $default }, )* )*
        ];

        /// All numeric parameters of a tyre property file, in SI units, one
        /// `f64` field per key of [`KEYS`] (field = key name in lower case).
        ///
        /// The struct is `#[repr(C)]` and holds only `f64`, so it can also be
        /// viewed as a slice indexed like [`KEYS`] ([`MfParams::as_slice`]),
        /// which is what the fitter uses.
        ///
        /// The scalar type is generic so that the Magic Formula equations can
        /// run on forward-mode dual numbers (exact parameter derivatives for
        /// the fitter); everything else uses the default `MfParams<f64>`.
        #[repr(C)]
        #[derive(Clone, Debug, PartialEq)]
        #[allow(missing_docs)]
        pub struct MfParams<T = f64> {
            $( $( pub $field: T, )* )*
        }

        impl<T: Copy> MfParams<T> {
            /// Convert every value with `f(index in KEYS, value)`, e.g. to
            /// dual numbers whose derivative part seeds selected parameters.
            #[allow(unused_assignments)]
            pub fn map<U>(&self, mut f: impl FnMut(usize, T) -> U) -> MfParams<U> {
                let mut i = 0usize;
                MfParams { $( $( $field: { let v = f(i, self.$field); i += 1; v }, )* )* }
            }
        }

        impl Default for MfParams<f64> {
            /// Every key at its default value.
            fn default() -> Self {
                MfParams { $( $( $field: $default, )* )* }
            }
        }
    };
}

tir_keys! {
    ["MODEL"]
    fittyp "FITTYP" One 0.0;
    use_mode "USE_MODE" One 124.0;
    longvl "LONGVL" Speed 16.7;
    vxlow "VXLOW" Speed 1.0;
    road_increment "ROAD_INCREMENT" Length 0.01;
    road_direction "ROAD_DIRECTION" One 1.0;
    hmax_local "HMAX_LOCAL" Time 2.5e-4;
    time_switch_integ "TIME_SWITCH_INTEG" Time 0.1;
    user_sub_id "USER_SUB_ID" One 815.0;
    n_tire_states "N_TIRE_STATES" One 4.0;
    switch_integ "SWITCH_INTEG" One 0.0;
    ["DIMENSION"]
    unloaded_radius "UNLOADED_RADIUS" Length 0.3135;
    width "WIDTH" Length 0.205;
    aspect_ratio "ASPECT_RATIO" One 0.6;
    rim_radius "RIM_RADIUS" Length 0.1905;
    rim_width "RIM_WIDTH" Length 0.152;
    ["OPERATING_CONDITIONS"]
    inflpres "INFLPRES" Pressure 220000.0;
    nompres "NOMPRES" Pressure 220000.0;
    ["INERTIA"]
    mass "MASS" Mass 9.3;
    ixx "IXX" Inertia 0.391;
    iyy "IYY" Inertia 0.736;
    belt_mass "BELT_MASS" Mass 7.0;
    belt_ixx "BELT_IXX" Inertia 0.34;
    belt_iyy "BELT_IYY" Inertia 0.6;
    gravity "GRAVITY" Acceleration -9.81;
    ["VERTICAL"]
    fnomin "FNOMIN" Force 4000.0;
    vertical_stiffness "VERTICAL_STIFFNESS" Stiffness 200000.0;
    vertical_damping "VERTICAL_DAMPING" Damping 50.0;
    mc_contour_a "MC_CONTOUR_A" One 0.5;
    mc_contour_b "MC_CONTOUR_B" One 0.5;
    breff "BREFF" One 8.4;
    dreff "DREFF" One 0.27;
    freff "FREFF" One 0.07;
    q_re0 "Q_RE0" One 1.0;
    q_v1 "Q_V1" One 0.0;
    q_v2 "Q_V2" One 0.0;
    q_fz2 "Q_FZ2" One 1.0e-4;
    q_fz3 "Q_FZ3" One 0.0;
    q_fcx "Q_FCX" One 0.0;
    q_fcy "Q_FCY" One 0.0;
    q_cam "Q_CAM" One 0.0;
    pfz1 "PFZ1" One 0.0;
    q_fcy2 "Q_FCY2" One 0.0;
    q_cam1 "Q_CAM1" One 0.0;
    q_cam2 "Q_CAM2" One 0.0;
    q_cam3 "Q_CAM3" One 0.0;
    q_fys1 "Q_FYS1" One 0.0;
    q_fys2 "Q_FYS2" One 0.0;
    q_fys3 "Q_FYS3" One 0.0;
    bottom_offst "BOTTOM_OFFST" Length 0.01;
    bottom_stiff "BOTTOM_STIFF" Stiffness 2000000.0;
    ["STRUCTURAL"]
    longitudinal_stiffness "LONGITUDINAL_STIFFNESS" Stiffness 300000.0;
    lateral_stiffness "LATERAL_STIFFNESS" Stiffness 100000.0;
    yaw_stiffness "YAW_STIFFNESS" TorsionStiffness 5000.0;
    freq_long "FREQ_LONG" Frequency 80.0;
    freq_lat "FREQ_LAT" Frequency 40.0;
    freq_yaw "FREQ_YAW" Frequency 50.0;
    freq_windup "FREQ_WINDUP" Frequency 70.0;
    damp_long "DAMP_LONG" One 0.04;
    damp_lat "DAMP_LAT" One 0.04;
    damp_yaw "DAMP_YAW" One 0.04;
    damp_windup "DAMP_WINDUP" One 0.04;
    damp_residual "DAMP_RESIDUAL" One 0.002;
    damp_vlow "DAMP_VLOW" One 0.001;
    q_bvx "Q_BVX" One 0.0;
    q_bvt "Q_BVT" One 0.0;
    pcfx1 "PCFX1" One 0.0;
    pcfx2 "PCFX2" One 0.0;
    pcfx3 "PCFX3" One 0.0;
    pcfy1 "PCFY1" One 0.0;
    pcfy2 "PCFY2" One 0.0;
    pcfy3 "PCFY3" One 0.0;
    pcmz1 "PCMZ1" One 0.0;
    ["CONTACT_PATCH"]
    q_ra1 "Q_RA1" One 0.5;
    q_ra2 "Q_RA2" One 1.0;
    q_rb1 "Q_RB1" One 1.0;
    q_rb2 "Q_RB2" One -1.0;
    ellips_shift "ELLIPS_SHIFT" One 0.8;
    ellips_length "ELLIPS_LENGTH" One 1.0;
    ellips_height "ELLIPS_HEIGHT" One 1.0;
    ellips_order "ELLIPS_ORDER" One 1.8;
    ellips_max_step "ELLIPS_MAX_STEP" Length 0.025;
    ellips_nwidth "ELLIPS_NWIDTH" One 10.0;
    ellips_nlength "ELLIPS_NLENGTH" One 10.0;
    env_c1 "ENV_C1" One 0.0;
    env_c2 "ENV_C2" One 0.0;
    q_a1 "Q_A1" One 0.0;
    q_a2 "Q_A2" One 0.0;
    ["INFLATION_PRESSURE_RANGE"]
    presmin "PRESMIN" Pressure 10000.0;
    presmax "PRESMAX" Pressure 1000000.0;
    ["VERTICAL_FORCE_RANGE"]
    fzmin "FZMIN" Force 100.0;
    fzmax "FZMAX" Force 10000.0;
    ["LONG_SLIP_RANGE"]
    kpumin "KPUMIN" One -1.5;
    kpumax "KPUMAX" One 1.5;
    ["SLIP_ANGLE_RANGE"]
    alpmin "ALPMIN" Angle -1.5;
    alpmax "ALPMAX" Angle 1.5;
    ["INCLINATION_ANGLE_RANGE"]
    cammin "CAMMIN" Angle -0.175;
    cammax "CAMMAX" Angle 0.175;
    ["SCALING_COEFFICIENTS"]
    lfzo "LFZO" One 1.0;
    lcx "LCX" One 1.0;
    lmux "LMUX" One 1.0;
    lex "LEX" One 1.0;
    lkx "LKX" One 1.0;
    lhx "LHX" One 1.0;
    lvx "LVX" One 1.0;
    lcy "LCY" One 1.0;
    lmuy "LMUY" One 1.0;
    ley "LEY" One 1.0;
    lky "LKY" One 1.0;
    lkyc "LKYC" One 1.0;
    lkzc "LKZC" One 1.0;
    lhy "LHY" One 1.0;
    lvy "LVY" One 1.0;
    ltr "LTR" One 1.0;
    lres "LRES" One 1.0;
    lxal "LXAL" One 1.0;
    lyka "LYKA" One 1.0;
    lvyka "LVYKA" One 1.0;
    ls "LS" One 1.0;
    lmx "LMX" One 1.0;
    lvmx "LVMX" One 1.0;
    lmy "LMY" One 1.0;
    lmp "LMP" One 1.0;
    lsgkp "LSGKP" One 1.0;
    lsgal "LSGAL" One 1.0;
    lgax "LGAX" One 1.0;
    lgay "LGAY" One 1.0;
    lgaz "LGAZ" One 1.0;
    lgyr "LGYR" One 1.0;
    lmuv "LMUV" One 0.0;
    lcz "LCZ" One 1.0;
    ["LONGITUDINAL_COEFFICIENTS"]
    pcx1 "PCX1" One 1.65;
    pdx1 "PDX1" One 1.3;
    pdx2 "PDX2" One -0.15;
    pdx3 "PDX3" One 0.0;
    pex1 "PEX1" One 0.0;
    pex2 "PEX2" One 0.0;
    pex3 "PEX3" One 0.0;
    pex4 "PEX4" One 0.0;
    pkx1 "PKX1" One 20.0;
    pkx2 "PKX2" One 0.0;
    pkx3 "PKX3" One 0.0;
    phx1 "PHX1" One 0.0;
    phx2 "PHX2" One 0.0;
    pvx1 "PVX1" One 0.0;
    pvx2 "PVX2" One 0.0;
    ppx1 "PPX1" One 0.0;
    ppx2 "PPX2" One 0.0;
    ppx3 "PPX3" One 0.0;
    ppx4 "PPX4" One 0.0;
    rbx1 "RBX1" One 20.0;
    rbx2 "RBX2" One 15.0;
    rbx3 "RBX3" One 0.0;
    rcx1 "RCX1" One 1.0;
    rex1 "REX1" One 0.0;
    rex2 "REX2" One 0.0;
    rhx1 "RHX1" One 0.0;
    ptx1 "PTX1" One 0.0;
    ptx2 "PTX2" One 0.0;
    ptx3 "PTX3" One 0.0;
    ["OVERTURNING_COEFFICIENTS"]
    qsx1 "QSX1" One 0.0;
    qsx2 "QSX2" One 0.0;
    qsx3 "QSX3" One 0.0;
    qsx4 "QSX4" One 5.0;
    qsx5 "QSX5" One 1.0;
    qsx6 "QSX6" One 10.0;
    qsx7 "QSX7" One 0.0;
    qsx8 "QSX8" One 0.0;
    qsx9 "QSX9" One 0.4;
    qsx10 "QSX10" One 0.0;
    qsx11 "QSX11" One 5.0;
    qsx12 "QSX12" One 0.0;
    qsx13 "QSX13" One 0.0;
    qsx14 "QSX14" One 0.0;
    ppmx1 "PPMX1" One 0.0;
    ["LATERAL_COEFFICIENTS"]
    pcy1 "PCY1" One 1.3;
    pdy1 "PDY1" One 1.1;
    pdy2 "PDY2" One -0.15;
    pdy3 "PDY3" One 0.0;
    pey1 "PEY1" One 0.0;
    pey2 "PEY2" One 0.0;
    pey3 "PEY3" One 0.0;
    pey4 "PEY4" One 0.0;
    pey5 "PEY5" One 0.0;
    pky1 "PKY1" One -20.0;
    pky2 "PKY2" One 1.0;
    pky3 "PKY3" One 0.0;
    pky4 "PKY4" One 2.0;
    pky5 "PKY5" One 0.0;
    pky6 "PKY6" One -1.0;
    pky7 "PKY7" One 0.0;
    phy1 "PHY1" One 0.0;
    phy2 "PHY2" One 0.0;
    phy3 "PHY3" One 0.0;
    pvy1 "PVY1" One 0.0;
    pvy2 "PVY2" One 0.0;
    pvy3 "PVY3" One 0.0;
    pvy4 "PVY4" One 0.0;
    ppy1 "PPY1" One 0.0;
    ppy2 "PPY2" One 0.0;
    ppy3 "PPY3" One 0.0;
    ppy4 "PPY4" One 0.0;
    ppy5 "PPY5" One 0.0;
    rby1 "RBY1" One 10.0;
    rby2 "RBY2" One 10.0;
    rby3 "RBY3" One 0.0;
    rby4 "RBY4" One 0.0;
    rcy1 "RCY1" One 1.0;
    rey1 "REY1" One 0.0;
    rey2 "REY2" One 0.0;
    rhy1 "RHY1" One 0.0;
    rhy2 "RHY2" One 0.0;
    rvy1 "RVY1" One 0.0;
    rvy2 "RVY2" One 0.0;
    rvy3 "RVY3" One 0.0;
    rvy4 "RVY4" One 20.0;
    rvy5 "RVY5" One 2.0;
    rvy6 "RVY6" One 10.0;
    pty1 "PTY1" One 0.0;
    pty2 "PTY2" One 0.0;
    ["ROLLING_COEFFICIENTS"]
    qsy1 "QSY1" One 0.01;
    qsy2 "QSY2" One 0.0;
    qsy3 "QSY3" One 4.0e-4;
    qsy4 "QSY4" One 4.0e-5;
    qsy5 "QSY5" One 0.0;
    qsy6 "QSY6" One 0.0;
    qsy7 "QSY7" One 0.85;
    qsy8 "QSY8" One -0.4;
    ["ALIGNING_COEFFICIENTS"]
    qbz1 "QBZ1" One 10.0;
    qbz2 "QBZ2" One 0.0;
    qbz3 "QBZ3" One 0.0;
    qbz4 "QBZ4" One 0.0;
    qbz5 "QBZ5" One 0.0;
    qbz6 "QBZ6" One 0.0;
    qbz9 "QBZ9" One 10.0;
    qbz10 "QBZ10" One 0.0;
    qcz1 "QCZ1" One 1.1;
    qdz1 "QDZ1" One 0.12;
    qdz2 "QDZ2" One 0.0;
    qdz3 "QDZ3" One 0.0;
    qdz4 "QDZ4" One 0.0;
    qdz6 "QDZ6" One 0.0;
    qdz7 "QDZ7" One 0.0;
    qdz8 "QDZ8" One -0.05;
    qdz9 "QDZ9" One 0.0;
    qdz10 "QDZ10" One 0.0;
    qdz11 "QDZ11" One 0.0;
    qez1 "QEZ1" One 0.0;
    qez2 "QEZ2" One 0.0;
    qez3 "QEZ3" One 0.0;
    qez4 "QEZ4" One 0.0;
    qez5 "QEZ5" One 0.0;
    qhz1 "QHZ1" One 0.0;
    qhz2 "QHZ2" One 0.0;
    qhz3 "QHZ3" One 0.0;
    qhz4 "QHZ4" One 0.0;
    ppz1 "PPZ1" One 0.0;
    ppz2 "PPZ2" One 0.0;
    ssz1 "SSZ1" One 0.0;
    ssz2 "SSZ2" One 0.0;
    ssz3 "SSZ3" One 0.0;
    ssz4 "SSZ4" One 0.0;
    qtz1 "QTZ1" One 0.0;
    mbelt "MBELT" Mass 0.0;
    ["TURNSLIP_COEFFICIENTS"]
    pdxp1 "PDXP1" One 0.4;
    pdxp2 "PDXP2" One 0.0;
    pdxp3 "PDXP3" One 0.0;
    pkyp1 "PKYP1" One 1.0;
    pdyp1 "PDYP1" One 0.4;
    pdyp2 "PDYP2" One 0.0;
    pdyp3 "PDYP3" One 0.0;
    pdyp4 "PDYP4" One 0.0;
    phyp1 "PHYP1" One 1.0;
    phyp2 "PHYP2" One 0.15;
    phyp3 "PHYP3" One 0.0;
    phyp4 "PHYP4" One -4.0;
    pecp1 "PECP1" One 0.5;
    pecp2 "PECP2" One 0.0;
    qdtp1 "QDTP1" One 10.0;
    qcrp1 "QCRP1" One 0.2;
    qcrp2 "QCRP2" One 0.1;
    qbrp1 "QBRP1" One 0.1;
    qdrp1 "QDRP1" One 1.0;
    qdrp2 "QDRP2" One 0.0;
}

const _: () = assert!(std::mem::size_of::<MfParams<f64>>() == N_KEYS * std::mem::size_of::<f64>());

impl MfParams<f64> {
    /// The parameters as a slice indexed like [`KEYS`].
    pub fn as_slice(&self) -> &[f64] {
        // SAFETY: `MfParams` is `#[repr(C)]` and consists of exactly `N_KEYS`
        // `f64` fields (checked by the const assertion above), so it has the
        // layout of `[f64; N_KEYS]`: no padding, f64 alignment.
        unsafe { std::slice::from_raw_parts(self as *const Self as *const f64, N_KEYS) }
    }

    /// The parameters as a mutable slice indexed like [`KEYS`].
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        // SAFETY: as in `as_slice`; the exclusive borrow of `self` is carried over.
        unsafe { std::slice::from_raw_parts_mut(self as *mut Self as *mut f64, N_KEYS) }
    }

    /// Value of a key by name (case-insensitive), if it is in the table.
    pub fn get(&self, name: &str) -> Option<f64> {
        key_index(name).map(|i| self.as_slice()[i])
    }

    /// Set a key by name (case-insensitive); returns `false` for unknown keys.
    pub fn set(&mut self, name: &str, value: f64) -> bool {
        match key_index(name) {
            Some(i) => {
                self.as_mut_slice()[i] = value;
                true
            }
            None => false,
        }
    }
}

/// Index of a key in [`KEYS`] (case-insensitive), if it is in the table.
pub fn key_index(name: &str) -> Option<usize> {
    KEYS.iter().position(|k| k.name.eq_ignore_ascii_case(name))
}

/// The table entry of a key (case-insensitive).
pub fn key_def(name: &str) -> Option<&'static KeyDef> {
    key_index(name).map(|i| &KEYS[i])
}

/// Other spellings of table keys that mean exactly the same parameter:
/// `(alias, key of the table)`. Only true synonyms belong here.
///
/// `LFZ0` (digit zero) is how several tools spell `LFZO` (letter O).
///
/// Deliberately NOT aliases: the legacy spellings `QFZ2`, `QFZ3`, `QV1`, `QV2`,
/// `QFCX1`, `QFCY1`, `QRE0` … of `Q_FZ2`, `Q_V1`, … MFeval 4.0 ignores them
/// (it uses its default Q_FZ2 = 1e-4 for a file that says `QFZ2 = 15.4`), and
/// tyrekit must reproduce MFeval's results, so they stay unknown keys: the
/// reader keeps them (and the writer writes them back) but does not use them.
pub const ALIASES: [(&str, &str); 1] = [("LFZ0", "LFZO")];

/// Index of a key in [`KEYS`] (case-insensitive), accepting the synonyms of
/// [`ALIASES`]. This is what the `.tir` reader uses.
pub fn lookup_key(name: &str) -> Option<usize> {
    key_index(name).or_else(|| {
        ALIASES
            .iter()
            .find(|(alias, _)| alias.eq_ignore_ascii_case(name))
            .and_then(|(_, key)| key_index(key))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_key_twice() {
        let mut names: Vec<&str> = KEYS.iter().map(|k| k.name).collect();
        names.sort_unstable();
        let before = names.len();
        names.dedup();
        assert_eq!(before, names.len(), "a key is declared twice in KEYS");
    }

    #[test]
    fn slice_view_matches_fields() {
        let mut p = MfParams::default();
        assert_eq!(p.get("PCY1"), Some(p.pcy1));
        assert!(p.set("pdy1", 0.987));
        assert_eq!(p.pdy1, 0.987);
        assert_eq!(p.as_slice()[key_index("PDY1").unwrap()], 0.987);
        assert_eq!(p.get("NOT_A_KEY"), None);
        // Field order equals table order: default of every slot is the table default.
        let d = MfParams::default();
        for (i, k) in KEYS.iter().enumerate() {
            assert_eq!(d.as_slice()[i].to_bits(), k.default.to_bits(), "{}", k.name);
        }
    }
}
