//! A run's own state (`bench -- checkpoint <file>`): the DEM alone and the coupled step on the
//! particles of any checkpoint (a job's, or a validation's in target/validate-cache), so that a
//! long run's cost per particle-step can be set beside the shipped bed's (`bench -- coupled`).
//! After a warm-up of WARMUP coupled steps, ROUNDS rounds of ROUND DEM-alone steps and ROUND
//! coupled steps, interleaved on one Simulation as in `scaling`; beside the costs, the pairs per
//! particle in the lists and in contact. Last line: {"bench":"checkpoint","particles","cells",
//! "threads","dem_ns_per_particle_step","coupled_ns_per_particle_step",…}.

use crate::coupled::{coupled_round, dem_round, Tally};
use fluidbed_core::sim::Simulation;
use serde_json::json;

const WARMUP: u64 = 100;
const ROUND: u64 = 200;
const ROUNDS: u64 = 3;

pub fn run() {
    let path = std::env::args().nth(2).expect("bench checkpoint <file>");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut sim = Simulation::restore(&bytes).unwrap_or_else(|e| panic!("{path}: {e}"));
    let n = sim.dem().len();
    // A finished run's checkpoint sits at its end time: give it room for the bench's steps.
    sim.set_end_time(sim.end_time().max(sim.time() + 1.0));
    coupled_round(&mut sim, WARMUP, &mut Tally::default());
    let (mut dem, mut cpl) = (Tally::default(), Tally::default());
    for _ in 0..ROUNDS {
        dem_round(&mut sim, ROUND, &mut dem);
        coupled_round(&mut sim, ROUND, &mut cpl);
    }
    let per = |t: &Tally| t.per_step() * 1e9 / n as f64;
    // The pair work per particle: listed pairs (Verlet and near lists) and touching pairs.
    let (outer, near) = sim.dem().list_sizes();
    let touching = sim.dem().touching_pairs().unwrap_or(0);
    let per_particle = |k: usize| k as f64 / n as f64;
    println!(
        "{}",
        json!({"bench": "checkpoint", "file": path, "particles": n, "cells": sim.grid().num_cells(),
            "time_s": sim.time(), "threads": rayon::current_num_threads(),
            "verlet_pairs_per_particle": per_particle(outer), "near_pairs_per_particle": per_particle(near),
            "touching_pairs_per_particle": per_particle(touching),
            "dem_ns_per_particle_step": per(&dem), "coupled_ns_per_particle_step": per(&cpl),
            "dem_stages_s_per_step": dem.stages_json(), "coupled_stages_s_per_step": cpl.stages_json()})
    );
}
