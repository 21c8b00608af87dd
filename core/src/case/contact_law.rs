//! The contact law a case chooses (`particles.contact_law`), by name as LAMMPS pair styles are.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Particle-particle and particle-wall contact law. Both take their damping from
/// `normal_damping` / `tangential_damping` and their friction from `sliding_friction`.
#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum ContactLawChoice {
    /// Hertz normal spring with Tsuji damping, Mindlin tangential spring with history and a
    /// Coulomb limit (PHYSICS.md 2; the paper's law), stiffness from `youngs_modulus_pa` and
    /// `poisson_ratio`.
    #[default]
    HertzMindlin,
    /// Linear spring–dashpot with tangential history, as LAMMPS `gran/hooke/history`:
    /// F_n = k_n δ + η_n dδ/dt, F_t = −k_t ξ − η_t v_t with the Coulomb limit, k_t = ratio · k_n.
    /// A restitution e gives η = 2ζ √(m* k) with ζ = −ln e / √(π² + ln² e) (exact for this law);
    /// a Tsuji α gives η = α √(m* k).
    LinearSpringDashpot {
        /// k_n (N/m), the same for pairs and walls.
        normal_stiffness_n_m: f64,
        /// k_t / k_n (2/7 is a common choice).
        tangential_stiffness_ratio: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::ContactLawChoice;

    #[test]
    fn contact_laws_are_chosen_by_name() {
        let hertz: ContactLawChoice = serde_json::from_str(r#""hertz_mindlin""#).unwrap();
        assert_eq!(hertz, ContactLawChoice::default());
        let text = r#"{"linear_spring_dashpot":{"normal_stiffness_n_m":2000,"tangential_stiffness_ratio":0.25}}"#;
        let linear: ContactLawChoice = serde_json::from_str(text).unwrap();
        let want =
            ContactLawChoice::LinearSpringDashpot { normal_stiffness_n_m: 2000.0, tangential_stiffness_ratio: 0.25 };
        assert_eq!(linear, want);
        assert!(serde_json::from_str::<ContactLawChoice>(r#""hooke""#).is_err(), "unknown names are refused");
    }
}
