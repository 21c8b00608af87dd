//! The case: what a user submits, as serde types with units in the field names.
//! Defaults are the paper's Table 1 (contacts) and section 3 (the 44-mm bed, d = 1.2 mm).
//! A case without a `gas` section runs DEM alone.

pub mod bounds;
mod contact_law;
mod run_checks;
pub mod strict_json;
mod validate;

pub use contact_law::ContactLawChoice;
pub use run_checks::{MAX_DEM_STEPS, MAX_INLET_MACH, WARN_INITIAL_OVERLAP_FRACTION};
pub use validate::{Problem, Severity, ValidationReport};

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// A complete simulation case.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Free-form name shown in job listings.
    #[serde(default)]
    pub name: String,
    pub column: Column,
    pub particles: Particles,
    pub bed: Bed,
    /// Magnitude of gravity, acting along -z.
    #[serde(default = "d_gravity")]
    pub gravity_m_s2: f64,
    #[serde(default)]
    pub dem: Dem,
    /// Simulated time at which the run ends.
    #[serde(default = "d_end_time")]
    pub end_time_s: f64,
    #[serde(default)]
    pub outputs: Outputs,
    /// The gas phase; absent means DEM only.
    #[serde(default)]
    pub gas: Option<Gas>,
    /// The cylindrical fluid grid (used when `gas` is present).
    #[serde(default)]
    pub grid: Grid,
    /// How particle volume becomes cell voidage.
    #[serde(default)]
    pub voidage: Voidage,
    /// The particle–gas exchange: drag law and how often voidage and drag are recomputed.
    #[serde(default)]
    pub coupling: Coupling,
    /// Analyses accumulated while the run goes (ΔP statistics, bubbles, rise velocity,
    /// particle-based time averages); the job's `/analysis`.
    #[serde(default)]
    pub analysis: AnalysisSpec,
}

/// The particle–gas exchange (paper section 2.3).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Coupling {
    /// Drag law (PHYSICS.md 1): "beetstra" (the paper's), "gidaspow" (Ergun + Wen–Yu), "di_felice".
    pub drag_law: crate::coupling::DragModel,
    /// DEM steps between recomputations of voidage and drag (1 = every step, the paper's); the
    /// drag on each particle is held in between, the gas still steps at its own stable step.
    /// Default 80 (100 µs at the paper's DEM step), with the gas's voidage interpolated, the drag
    /// on the gas implicit and the pressure force at the interval's mean (docs/BENCHMARKS.md,
    /// "Longer intervals"); an interval longer than tested for the other coupling settings warns
    /// (25 µs with the gas's voidage held, 50 µs with the drag on the gas held, else 100 µs).
    #[serde(default = "d_coupling_interval")]
    pub interval_steps: u32,
    /// Sub-layers of each fluid layer for the voidage the drag law reads (1 = the cell's voidage,
    /// the paper's model). With n > 1 a particle's drag takes the voidage ε_s of the sub-layer of
    /// height dz/n holding its centre (averaged with the sub-layers above and below) and the
    /// interstitial velocity ε_c·u_c/ε_s of a gas flux uniform over the cell, and its share of the
    /// sub-layer's pressure drop; the gas equations keep the cell's voidage ε_c
    /// (coupling/exchange.rs). At the bed surface and the plate it stands in for layers thinner
    /// than the cells (docs/VALIDATION.md, "U_mf with the paper's cells and the drag voidage on sub-layers").
    #[serde(default = "d_drag_sublayers")]
    pub drag_voidage_sublayers: u32,
    /// The gas's voidage between couplings: "interpolated" (the default: from the previous
    /// coupling's field to the new one over the next interval, one interval behind the particles
    /// and without steps), "held" (the paper's: each coupling's field at once; the gas mass of
    /// each cell is held, so the change shows as a pressure step, which sets off an oscillation
    /// of the coupling at intervals over 25 µs) or "extrapolated" (the new field
    /// moved on at the last interval's rate: no delay, steps of the second difference only;
    /// cfd/voidage_ramp.rs).
    #[serde(default)]
    pub gas_voidage: GasVoidage,
    /// The particles' pressure-gradient force −V_p∇p between couplings: "interval_mean" (the
    /// default: held, at the mean of the gas's ∇p over its steps of the last interval, so the
    /// particles receive the pressure impulse the gas felt, one interval late, at no cost between
    /// couplings; sim/pressure_mean.rs), "held" (the paper's: with the drag, from the coupling's
    /// gas state) or "gas_step" (it follows the gas at each of its steps while the drag stays
    /// held; sim/pressure_follow.rs). docs/VALIDATION.md "The pressure force between couplings".
    /// Always written: a stored case without it is from before "interval_mean" became the
    /// default and means "held" (`Case::from_stored_json`).
    #[serde(default)]
    pub pressure_force: PressureForce,
    /// The drag on the gas between couplings: "implicit" (the default: linearised in the gas
    /// velocity about the coupling's, with the particles' drag coefficient, and stepped by
    /// backward Euler at each gas step, so that the gas's drag relaxation, ≈60 µs in a bed near
    /// U_mf, needs no short interval; cfd/implicit_drag.rs) or "held" (the paper's: the coupling's
    /// force, as the particles get). Always written: a stored case without it is from before
    /// this key and means "held" (`Case::from_stored_json`).
    #[serde(default)]
    pub gas_drag: GasDrag,
}

/// The drag on the gas between couplings (`coupling.gas_drag`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GasDrag {
    Held,
    #[default]
    Implicit,
}

/// The particles' pressure-gradient force between couplings (`coupling.pressure_force`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum PressureForce {
    Held,
    GasStep,
    #[default]
    IntervalMean,
}

/// How the gas's voidage moves between couplings (`coupling.gas_voidage`).
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum GasVoidage {
    Held,
    #[default]
    Interpolated,
    Extrapolated,
}

impl Default for Coupling {
    fn default() -> Self {
        Coupling {
            drag_law: Default::default(),
            interval_steps: d_coupling_interval(),
            drag_voidage_sublayers: d_drag_sublayers(),
            gas_voidage: GasVoidage::Interpolated,
            pressure_force: PressureForce::IntervalMean,
            gas_drag: GasDrag::Implicit,
        }
    }
}

fn d_drag_sublayers() -> u32 {
    1
}

fn d_coupling_interval() -> u32 {
    80
}

/// The cylindrical column (tube). Its axis is the z axis, the distributor plate is z = 0.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Column {
    pub diameter_m: f64,
    pub height_m: f64,
    /// Close the top with a wall at z = height_m (particles bounce off it).
    #[serde(default)]
    pub lid: bool,
}

impl Default for Column {
    fn default() -> Self {
        Column { diameter_m: 0.044, height_m: 0.12, lid: false }
    }
}

/// Normal or tangential damping: Tsuji's α, or a restitution coefficient converted to α.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Damping {
    TsujiAlpha(f64),
    Restitution(f64),
}

impl Damping {
    /// Tsuji α. Restitution e maps to α = √5 |ln e| / √(ln²e + π²) (PHYSICS.md 2.4).
    pub fn alpha(&self) -> f64 {
        match *self {
            Damping::TsujiAlpha(a) => a,
            Damping::Restitution(e) => alpha_from_restitution(e),
        }
    }
}

/// PHYSICS.md 2.4: α = √5·|ln e| / √(ln²e + π²).
pub fn alpha_from_restitution(e: f64) -> f64 {
    let l = e.ln();
    5f64.sqrt() * l.abs() / (l * l + std::f64::consts::PI.powi(2)).sqrt()
}

/// PHYSICS.md 2.4: e = exp(−π α / √(5 − α²)).
pub fn restitution_from_alpha(alpha: f64) -> f64 {
    (-std::f64::consts::PI * alpha / (5.0 - alpha * alpha).sqrt()).exp()
}

/// Monodisperse spheres and their contact parameters (paper Table 1).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Particles {
    pub diameter_m: f64,
    pub density_kg_m3: f64,
    pub youngs_modulus_pa: f64,
    pub poisson_ratio: f64,
    pub sliding_friction: f64,
    pub normal_damping: Damping,
    pub tangential_damping: Damping,
    /// The contact law by name (default: Hertz–Mindlin with Tsuji damping).
    pub contact_law: ContactLawChoice,
}

impl Default for Particles {
    fn default() -> Self {
        Particles {
            diameter_m: 0.0012,
            density_kg_m3: 1000.0,
            youngs_modulus_pa: 1.2e8,
            poisson_ratio: 0.33,
            sliding_friction: 0.1,
            normal_damping: Damping::TsujiAlpha(0.02),
            tangential_damping: Damping::TsujiAlpha(1e-4),
            contact_law: ContactLawChoice::HertzMindlin,
        }
    }
}

/// The initial bed: poured and settled from a seed, or given particle by particle.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Bed {
    /// Random insertion and settling under gravity. Give exactly one of the two sizes.
    Generated(GeneratedBed),
    /// Explicit particle positions (and optional velocities), in metres and m/s.
    Explicit(ExplicitBed),
}

impl Default for Bed {
    fn default() -> Self {
        Bed::Generated(GeneratedBed::default())
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct GeneratedBed {
    /// Target settled ("tapped") bed height.
    #[serde(default)]
    pub settled_height_m: Option<f64>,
    /// Or an exact particle count.
    #[serde(default)]
    pub count: Option<usize>,
    /// Seed of the random insertion; the same seed gives the same bed.
    #[serde(default = "d_seed")]
    pub seed: u64,
}

impl Default for GeneratedBed {
    fn default() -> Self {
        GeneratedBed { settled_height_m: Some(0.03), count: None, seed: 1 }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ExplicitBed {
    pub positions_m: Vec<[f64; 3]>,
    #[serde(default)]
    pub velocities_m_s: Option<Vec<[f64; 3]>>,
}

/// DEM integration settings.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Dem {
    /// DEM time step (paper Table 1: 1.25 µs).
    #[serde(default = "d_dem_dt")]
    pub time_step_s: f64,
    /// Verlet skin as a fraction of the particle diameter.
    #[serde(default = "d_skin")]
    pub skin_fraction: f64,
    /// Hold particles fixed after the bed is built (packed-bed runs): no contact work at all.
    #[serde(default)]
    pub frozen: bool,
    /// Worker threads for this run (0 = the pool's default).
    #[serde(default)]
    pub threads: usize,
    /// The same bits for any thread count (a fixed work split of the pair pass; docs/BENCHMARKS.md
    /// gives its cost); off, the split follows the thread count (the fast default).
    #[serde(default)]
    pub reproducible: bool,
}

impl Default for Dem {
    fn default() -> Self {
        Dem { time_step_s: d_dem_dt(), skin_fraction: d_skin(), frozen: false, threads: 0, reproducible: false }
    }
}

/// Fields a snapshot may carry.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, JsonSchema, PartialEq, Eq, Hash)]
#[serde(rename_all = "snake_case")]
pub enum Field {
    Voidage,
    Pressure,
    GasVelocity,
    Particles,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Outputs {
    /// Simulated time between snapshots.
    #[serde(default = "d_snapshot_interval")]
    pub snapshot_interval_s: f64,
    /// Fields stored in each snapshot.
    #[serde(default = "d_fields")]
    pub fields: Vec<Field>,
    /// Simulated time between checkpoints (0 = at every snapshot).
    #[serde(default)]
    pub checkpoint_interval_s: f64,
}

impl Default for Outputs {
    fn default() -> Self {
        Outputs { snapshot_interval_s: d_snapshot_interval(), fields: d_fields(), checkpoint_interval_s: 0.0 }
    }
}

/// What the run's analysis samples and over which window (sim/run_analysis.rs).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct AnalysisSpec {
    /// Start of the averaging window (simulated s); the start-up before it is not sampled.
    pub from_s: f64,
    /// Simulated time between samples (rounded to whole DEM steps).
    pub sample_interval_s: f64,
    /// Heights above the distributor of the two cross-sections whose voidage correlation gives
    /// the bubble rise velocity, lower first (m); absent = 30% and 70% of the time-averaged bed height.
    pub rise_heights_m: Option<[f64; 2]>,
    /// Heights of the radial profiles (m); absent = half the time-averaged bed height.
    pub profile_heights_m: Vec<f64>,
    /// Cell voidage above which a cell counts as bubble.
    pub bubble_voidage: f64,
}

impl Default for AnalysisSpec {
    fn default() -> Self {
        AnalysisSpec {
            from_s: 0.0,
            sample_interval_s: 0.002,
            rise_heights_m: None,
            profile_heights_m: Vec::new(),
            bubble_voidage: crate::analysis::bubble_fraction::DEFAULT_BUBBLE_VOIDAGE,
        }
    }
}

/// The gas: isothermal, compressible (PHYSICS.md 8), model-A coupling (PHYSICS.md 11).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Gas {
    /// Superficial velocity set at the distributor after the ramp.
    pub superficial_velocity_m_s: f64,
    /// Linear ramp of the inlet velocity from zero (paper: 240 ms).
    #[serde(default = "d_ramp")]
    pub ramp_time_s: f64,
    #[serde(default = "d_temperature")]
    pub temperature_k: f64,
    /// Specific gas constant R_s; a = √(R_s T) (air: 287.05).
    #[serde(default = "d_rs")]
    pub specific_gas_constant_j_kg_k: f64,
    #[serde(default = "d_mu")]
    pub viscosity_pa_s: f64,
    /// Bulk viscosity L (Stokes' hypothesis: 0).
    #[serde(default)]
    pub bulk_viscosity_pa_s: f64,
    /// Absolute pressure at the outlet (initial state and relaxation target).
    #[serde(default = "d_p_out")]
    pub outlet_pressure_pa: f64,
    /// Voidage assigned to the inlet cells below the distributor (paper Table 2: 0.4).
    #[serde(default = "d_inlet_voidage")]
    pub inlet_voidage: f64,
    /// Poinsot-Lele relaxation σ of the outlet toward outlet_pressure_pa: the mean pressure relaxes in
    /// H/(σa) (10 ms in a 0.066-m column at the default 0.02), a 0.05-m pulse reflects 0.87 % (2.2 % at
    /// σ = 0.25); 0 is perfectly non-reflecting and leaves the column where the inflow ramp pushed it.
    #[serde(default = "d_sigma")]
    pub outlet_relaxation: f64,
    /// Gas time step; absent = the largest stable step, sub-cycled within the DEM step.
    #[serde(default)]
    pub time_step_s: Option<f64>,
    /// Lower clamp of ε in the drag law (PHYSICS.md 1.1).
    #[serde(default = "d_eps_min")]
    pub drag_voidage_min: f64,
    /// Safety factor on the largest stable gas step (acoustic CFL inside AB3's stability
    /// region, PHYSICS.md 7); the stable step is this factor times the limit.
    #[serde(default = "d_cfl")]
    pub cfl_factor: f64,
    /// Speed of the gas's pressure waves as a fraction f of the isothermal sound speed a = √(R_s T):
    /// equation of state p = p_out + (f a)²(ρ − ρ_out), a reduced speed of sound for low-Mach flow
    /// (docs/VALIDATION.md "Acoustic speed"). 1 = the paper's gas; below 1 the stable gas step
    /// grows as 1/f and the density stays within Δp/(f a)² of ρ_out.
    #[serde(default = "d_acoustic_speed_factor")]
    pub acoustic_speed_factor: f64,
    /// Time scheme of the gas: "forward_backward" (the default: the acoustic terms
    /// forward–backward, the rest AB3, a stable step 2.07× AB3's) or "ab3" (the paper's, PHYSICS.md
    /// 7, on the whole right-hand side); docs/VALIDATION.md "Forward–backward gas step".
    #[serde(default, skip_serializing_if = "crate::cfd::TimeScheme::is_default")]
    pub time_scheme: crate::cfd::TimeScheme,
    /// A jet through the distributor's inner annuli over a time window (absent: the paper's uniform
    /// distributor); e.g. one injected bubble in a bed held at U_mf.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inlet_jet: Option<InletJet>,
}

/// `gas.inlet_jet`: the inlet cells of the grid's `annuli` inner annuli (radius annuli·dr) blow at
/// their own superficial velocity from `from_s` until `until_s` (absent: to the end), the rest of
/// the distributor at `superficial_velocity_m_s`; the inlet ramp applies to both.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct InletJet {
    pub annuli: usize,
    pub superficial_velocity_m_s: f64,
    #[serde(default)]
    pub from_s: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub until_s: Option<f64>,
}

impl Default for Gas {
    fn default() -> Self {
        Gas {
            superficial_velocity_m_s: 0.6,
            ramp_time_s: d_ramp(),
            temperature_k: d_temperature(),
            specific_gas_constant_j_kg_k: d_rs(),
            viscosity_pa_s: d_mu(),
            bulk_viscosity_pa_s: 0.0,
            outlet_pressure_pa: d_p_out(),
            inlet_voidage: d_inlet_voidage(),
            outlet_relaxation: d_sigma(),
            time_step_s: None,
            drag_voidage_min: d_eps_min(),
            cfl_factor: d_cfl(),
            acoustic_speed_factor: d_acoustic_speed_factor(),
            time_scheme: Default::default(),
            inlet_jet: None,
        }
    }
}

impl Gas {
    /// Isothermal sound speed a = √(R_s T) (PHYSICS.md 8).
    pub fn sound_speed_m_s(&self) -> f64 {
        (self.specific_gas_constant_j_kg_k * self.temperature_k).sqrt()
    }
    /// Speed of the solver's pressure waves, f·a (`acoustic_speed_factor`).
    pub fn acoustic_speed_m_s(&self) -> f64 {
        self.acoustic_speed_factor * self.sound_speed_m_s()
    }
    /// Density at the outlet pressure, ρ = p / a².
    pub fn outlet_density_kg_m3(&self) -> f64 {
        self.outlet_pressure_pa / (self.specific_gas_constant_j_kg_k * self.temperature_k)
    }
}

/// The equal-volume cylindrical grid: N_r = D/(2 dr) annuli, annulus i holds n0·(2i+1) cells.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct Grid {
    /// Radial spacing; must divide the column radius into whole annuli.
    pub dr_m: f64,
    /// Axial spacing; absent = the value nearest dr that divides the column height.
    #[serde(default)]
    pub dz_m: Option<f64>,
    /// Cells in the central annulus (≥ 3). Default 3: the cell's arc length π·dr/n0 ≈ 1.05 dr,
    /// so cells are as near square as the equal-volume rule allows.
    #[serde(default = "d_n0")]
    pub n0: usize,
}

impl Default for Grid {
    fn default() -> Self {
        Grid { dr_m: 0.0044, dz_m: None, n0: d_n0() }
    }
}

/// Split of a particle's volume onto boxes in the square-grid method.
#[derive(Clone, Copy, Debug, Serialize, Deserialize, JsonSchema, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum BoxSplit {
    /// Khawaja et al. (2012) cube of side `cube_side_factor`·d (PHYSICS.md 4).
    Cuboid,
    /// Exact sphere-box volumes (PHYSICS.md 3).
    Exact,
}

/// How particle volume is turned into cell voidage (paper section 1 and 2.3).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Voidage {
    /// Whole particle volume in the cell of its centre (paper eq. 2).
    Direct,
    /// Direct method over the cell and its face neighbours (paper eq. 3).
    Grouping,
    /// Box grid mapped onto the cells (paper eq. 8-9).
    SquareGrid {
        /// Horizontal box side dl_xy; absent = just above d (configuration 3: 1.375 mm for d = 1.2 mm).
        #[serde(default)]
        box_side_m: Option<f64>,
        #[serde(default = "d_split")]
        split: BoxSplit,
        /// Cube side over d for the cuboid split (paper: 1).
        #[serde(default = "d_one")]
        cube_side_factor: f64,
    },
    /// Exact sphere volume split straight onto the cylindrical cells: exact per fluid layer,
    /// exact slice areas on the polar cells integrated by Gauss–Legendre in z (ours).
    ExactCylindrical,
}

/// Default: the paper's square grid, configuration 3 (boxes just above d), cuboid split.
/// Measured (docs/BENCHMARKS.md "## Voidage", 44-mm grid): mean cell-voidage error 1e-2 for
/// ~0.05 µs per particle per coupling step; `exact_cylindrical` is ~100× more accurate (1e-4)
/// but costs ~0.66 µs, and the voidage is recomputed at every gas step (every 1-2 DEM steps), so
/// it would cost several times the contact work itself (quickstart: square-grid voidage 30 s
/// against DEM 30 s of a 120-s run). Choose `exact_cylindrical` where accuracy of the voidage
/// field matters more than run time.
impl Default for Voidage {
    fn default() -> Self {
        Voidage::SquareGrid { box_side_m: None, split: BoxSplit::Cuboid, cube_side_factor: 1.0 }
    }
}

impl Voidage {
    /// The methods of the paper's Fig. 3, by name, and the exact split beside them: direct,
    /// grouping, the square grid of configuration 3 for d = 1.2 mm (1.375-mm boxes, cuboid split),
    /// exact_cylindrical.
    pub fn fig3_methods() -> [(&'static str, Voidage); 4] {
        [
            ("direct", Voidage::Direct),
            ("grouping", Voidage::Grouping),
            (
                "square_grid",
                Voidage::SquareGrid { box_side_m: Some(0.001375), split: BoxSplit::Cuboid, cube_side_factor: 1.0 },
            ),
            ("exact_cylindrical", Voidage::ExactCylindrical),
        ]
    }
}

impl Case {
    /// Parse JSON (serde errors name the line and column).
    pub fn from_json(s: &str) -> Result<Case, serde_json::Error> {
        serde_json::from_str(s)
    }
    /// A case as this program stored it (a checkpoint's, a job's): as `from_json`, except that
    /// a coupling without `pressure_force` or `gas_drag` was stored before that key was always
    /// written, when its absence meant "held", and is read so.
    pub fn from_stored_json(s: &str) -> Result<Case, serde_json::Error> {
        let mut v: serde_json::Value = serde_json::from_str(s)?;
        if let Some(case) = v.as_object_mut() {
            let coupling = case.entry("coupling").or_insert_with(|| serde_json::json!({}));
            if let Some(c) = coupling.as_object_mut() {
                c.entry("pressure_force").or_insert_with(|| "held".into());
                c.entry("gas_drag").or_insert_with(|| "held".into());
            }
        }
        serde_json::from_value(v)
    }
    /// The JSON Schema of a case (published as docs/case.schema.json).
    pub fn json_schema() -> serde_json::Value {
        serde_json::to_value(schemars::schema_for!(Case)).expect("schema serialises")
    }
    /// Particle volume V_p = π d³ / 6.
    pub fn particle_volume_m3(&self) -> f64 {
        std::f64::consts::PI * self.particles.diameter_m.powi(3) / 6.0
    }
    /// Particle mass m = ρ_p V_p.
    pub fn particle_mass_kg(&self) -> f64 {
        self.particles.density_kg_m3 * self.particle_volume_m3()
    }
    /// Axial grid spacing actually used: the given dz, or the height split into layers nearest dr.
    pub fn grid_dz_m(&self) -> f64 {
        match self.grid.dz_m {
            Some(dz) => dz,
            None => {
                let n = (self.column.height_m / self.grid.dr_m).round().max(1.0);
                self.column.height_m / n
            }
        }
    }
    /// Undamped Hertz contact time between two particles at impact speed v0 (PHYSICS.md 2.4):
    /// t_c = 2.868 (m*² / (R* E*² v0))^(1/5).
    pub fn hertz_contact_time_s(&self, v0: f64) -> f64 {
        let p = &self.particles;
        let r = p.diameter_m / 2.0;
        let m_star = self.particle_mass_kg() / 2.0;
        let r_star = r / 2.0;
        let e_star = p.youngs_modulus_pa / (2.0 * (1.0 - p.poisson_ratio * p.poisson_ratio));
        2.868 * (m_star * m_star / (r_star * e_star * e_star * v0)).powf(0.2)
    }
}

/// Least impact speed the DEM step is checked at (`largest_impact_speed_m_s` takes the case's own).
pub const CHECK_IMPACT_SPEED_M_S: f64 = 1.0;

fn d_gravity() -> f64 {
    9.81
}
fn d_end_time() -> f64 {
    1.0
}
fn d_seed() -> u64 {
    1
}
fn d_dem_dt() -> f64 {
    1.25e-6
}
fn d_skin() -> f64 {
    0.3
}
fn d_snapshot_interval() -> f64 {
    0.01
}
fn d_fields() -> Vec<Field> {
    vec![Field::Voidage, Field::Pressure]
}
fn d_ramp() -> f64 {
    0.24
}
fn d_temperature() -> f64 {
    293.15
}
fn d_rs() -> f64 {
    287.05
}
fn d_mu() -> f64 {
    1.8e-5
}
fn d_p_out() -> f64 {
    101_325.0
}
fn d_inlet_voidage() -> f64 {
    0.4
}
fn d_sigma() -> f64 {
    0.02
}
fn d_eps_min() -> f64 {
    0.1
}
fn d_cfl() -> f64 {
    0.9
}
fn d_acoustic_speed_factor() -> f64 {
    1.0
}
fn d_n0() -> usize {
    3
}
fn d_split() -> BoxSplit {
    BoxSplit::Cuboid
}
fn d_one() -> f64 {
    1.0
}

#[cfg(test)]
mod run_checks_tests;
#[cfg(test)]
mod tests;
