#ifndef KINCAL_TESTS_TESTING_ISO9283_CYCLES_H_
#define KINCAL_TESTS_TESTING_ISO9283_CYCLES_H_

// Simulated ISO 9283 cycles for the tests: a true robot (the robot file's
// chain with a hidden backlash on one joint, plus optional extra
// geometry) visits P1..P5 cycle after cycle; the tip is measured with
// Gaussian noise in a rotated, shifted instrument frame. Rows in visit
// order, fixed_point = the pose's label; an unlabelled warm-up cycle first,
// so the first measured cycle is approached like every other one.

#include <random>
#include <string>
#include <vector>

#include "calib/chain.h"
#include "data/observations.h"
#include "data/rigid3.h"
#include "data/robot.h"

namespace kincal::testing {

struct IsoSimulation {
  std::vector<std::vector<double>> poses;  // P1..P5, joint readings
  std::vector<int> order;                  // one cycle, indices into poses
  int cycles = 30;
  int backlash_joint = 1;
  double backlash_deg = 0.0;  // full width b (deg, or mm when prismatic)
  double noise_mm = 0.01;     // per axis
  uint64_t seed = 7;
  // 0: unidirectional (the standard's cycle). > 0: each pose is approached
  // through an unlabelled via row with the backlash joint +delta (even
  // cycles) or -delta (odd cycles) away: its approach direction flips every
  // cycle.
  double via_delta_deg = 0.0;
  // Extra error of the true robot's row geometry: (row, index, value in
  // internal units) added to the chain's row blocks.
  struct RowError {
    int row = 0, index = 0;
    double value = 0.0;
  };
  std::vector<RowError> geometry_errors;
  Rigid3 meas_from_base;
};

inline Rigid3 IsoInstrumentFrame() {
  Rigid3 t;
  t.R = RotationMatrixFromVector(Eigen::Vector3d(0.3, -0.2, 1.1));
  t.t = Eigen::Vector3d(1500.0, -300.0, 800.0);
  return t;
}

inline Observation IsoRow(const std::string& pose, const std::vector<double>& q,
                          const std::string& label) {
  Observation o;
  o.pose = pose;
  o.q = q;
  o.fixed_point = label;
  return o;
}

// The standard's cycle (ISO 9283 7.2.1: from P1 through P5, P4, P3, P2
// back to P1).
inline std::vector<int> IsoStandardOrder() { return {0, 4, 3, 2, 1}; }

// BH-7 (j1 mm, j2..j5 deg), backlash on j2: every joint moves between
// successive poses.
inline IsoSimulation Bh7IsoSimulation() {
  IsoSimulation sim;
  sim.poses = {{75, 20, 70, 150, -40},
               {40, -10, 100, 120, -20},
               {110, 40, 40, 170, -60},
               {60, 50, 80, 130, -30},
               {90, 0, 60, 160, -50}};
  sim.order = IsoStandardOrder();
  sim.backlash_joint = 1;
  sim.meas_from_base = IsoInstrumentFrame();
  return sim;
}

// UR10 (deg), backlash on shoulder_lift_joint.
inline IsoSimulation Ur10IsoSimulation() {
  IsoSimulation sim;
  sim.poses = {{0, -90, 90, -90, -90, 0},
               {20, -70, 70, -80, -90, 10},
               {-20, -110, 100, -70, -80, -10},
               {10, -100, 60, -100, -100, 20},
               {-10, -80, 110, -90, -70, -20}};
  sim.order = IsoStandardOrder();
  sim.backlash_joint = 1;
  sim.meas_from_base = IsoInstrumentFrame();
  return sim;
}

inline Observations SimulateIsoCycles(const Robot& robot,
                                      const IsoSimulation& sim) {
  Observations obs;
  obs.source = "simulated";
  for (const auto& j : robot.joints) obs.joint_names.push_back(j.name);
  for (int c = -1; c < sim.cycles; ++c) {
    for (int k : sim.order) {
      const std::string label = "P" + std::to_string(k + 1);
      const std::string id = "c" + std::to_string(c + 1) + "_" + label;
      if (sim.via_delta_deg > 0) {
        std::vector<double> via = sim.poses[k];
        via[sim.backlash_joint] +=
            (c % 2 == 0 ? 1.0 : -1.0) * sim.via_delta_deg;
        obs.rows.push_back(IsoRow(id + "_via", via, ""));
      }
      obs.rows.push_back(IsoRow(id, sim.poses[k], c < 0 ? "" : label));
    }
  }
  Chain truth = Chain::FromRobot(robot);
  const bool revolute =
      truth.rows[sim.backlash_joint].type == JointType::kRevolute;
  truth.joint_errors[sim.backlash_joint][kBacklash] =
      sim.backlash_deg * (revolute ? M_PI / 180.0 : 1.0);
  for (const auto& e : sim.geometry_errors) {
    truth.rows[e.row].p[e.index] += e.value;
  }
  const std::vector<PoseInput> inputs = MakePoseInputs(truth, obs);
  std::mt19937_64 rng(sim.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (size_t i = 0; i < obs.rows.size(); ++i) {
    Observation& o = obs.rows[i];
    if (o.fixed_point.empty()) continue;
    const Eigen::Vector3d e(noise(rng), noise(rng), noise(rng));
    o.has_point = true;
    o.p_in_meas =
        sim.meas_from_base * TipInBase(truth, inputs[i]) + sim.noise_mm * e;
  }
  return obs;
}

// The nominal tip with joint `joint` moved by `delta` (reading units) from
// `q`.
inline Eigen::Vector3d IsoNominalTip(const Robot& robot, std::vector<double> q,
                                     int joint, double delta) {
  q[joint] += delta;
  Observations one;
  one.source = "tip";
  for (const auto& j : robot.joints) one.joint_names.push_back(j.name);
  one.rows.push_back(IsoRow("p", q, ""));
  const Chain chain = Chain::FromRobot(robot);
  return TipInBase(chain, MakePoseInputs(chain, one)[0]);
}

}  // namespace kincal::testing

#endif  // KINCAL_TESTS_TESTING_ISO9283_CYCLES_H_
