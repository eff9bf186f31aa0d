// kincal plan: choose the robot poses of a calibration experiment (design of
// experiments on the identification Jacobian, plan/plan.h), or with
// --iso9283 the poses of ISO 9283's pose-accuracy test (plan/iso9283_cube.h).

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>

#include "app/app_util.h"
#include "app/command.h"
#include "camcal/rig.h"
#include "data/atomic_file.h"
#include "data/error.h"
#include "data/progress.h"
#include "data/rigid3.h"
#include "data/urdf.h"
#include "data/warnings.h"
#include "plan/confirm.h"
#include "plan/iso9283_cube.h"
#include "plan/link_geometry.h"
#include "plan/obstacles.h"
#include "plan/plan.h"
#include "vision/target.h"

namespace kincal::app {
namespace {

struct PlanArgs {
  std::string robot, root, tip, out, random_out, rig, target, obstacles;
  std::vector<double> rig_from_base;
  std::string criterion = "sigma";
  int confirm = 0;
  PlanOptions options;
  bool json = false;
  bool no_self_collision = false;
  // --iso9283: the cube's test poses instead of a calibration design.
  bool iso9283 = false;
  IsoCubeOptions cube;
  std::vector<double> cube_center, orientation;
  // Options given on the command line that only a calibration design uses.
  std::vector<std::string> design_only;
  bool n_given = false;
  bool cube_option_given = false;  // --cube, --cycles, ...
  // Where the link capsules come from ("urdf collision" or "capsules") and
  // why a URDF's collision geometry was not used (code
  // urdf_collision_unused).
  std::string link_geometry = "capsules";
  std::vector<Warning> warnings;
};

// A URDF robot's links from its <collision> geometry (plan/link_geometry.h);
// the generic capsules otherwise, with a warning on stderr when the URDF's
// geometry cannot be used.
void UseUrdfCollisionGeometry(const Robot& robot, PlanArgs* args) {
  const std::string& path = args->robot;
  if (path.size() < 5 || path.compare(path.size() - 5, 5, ".urdf") != 0) {
    return;
  }
  LinkGeometry links = ReadUrdfLinkGeometry(path, robot, args->root);
  Warnings warnings = CommandWarnings();
  for (const std::string& w : links.warnings) {
    warnings.Add("urdf_collision_unused", w);
  }
  args->warnings = warnings.list();
  if (links.empty()) return;
  MarkAlwaysTouching(Chain::FromRobot(robot), robot, &links);
  args->link_geometry = "urdf collision";
  args->options.safety.links = std::move(links);
}

// Each joint's coverage: travel, largest gap, whether it is wide.
nlohmann::json CoverageJson(const std::vector<JointCoverage>& coverage) {
  nlohmann::json out = nlohmann::json::array();
  for (const JointCoverage& c : coverage) {
    out.push_back({{"joint", c.joint},
                   {"circular", c.circular},
                   {"travel", {Number(c.lo), Number(c.hi)}},
                   {"largest_gap", Number(c.Gap())},
                   {"gap", {Number(c.from), Number(c.to)}},
                   {"wide", c.wide}});
  }
  return out;
}

// A campaign for the diagnosis (--criterion coverage) whose poses still
// leave a joint a wide gap (more poses, or obstacles and visibility that
// close part of the travel): a warning naming the joint and the gap.
void AddCoverageWarnings(const PlanResult& plan, PlanArgs* args) {
  if (args->options.criterion != PlanOptions::kCoverage) return;
  Warnings warnings = CommandWarnings();
  for (const JointCoverage& c : plan.planned_coverage) {
    if (!c.wide) continue;
    std::ostringstream os;
    os.precision(4);
    os << "joint '" << c.joint << "': the planned poses leave " << c.Gap()
       << " of its " << (c.circular ? "turn" : "travel") << " without a "
       << "reading (" << c.from << " .. " << c.to << "), over 10 % of it: "
       << "a joint error fitted on them is not supported there; plan more "
       << "poses (--n), or widen what --obstacles, --limit-margin and the "
       << "rig leave reachable";
    warnings.Add("travel_gap", os.str());
  }
  for (const Warning& w : warnings.list()) args->warnings.push_back(w);
}

// The safety fields both JSON objects share.
void SafetyJson(const PlanArgs& args, nlohmann::json* j) {
  (*j)["link_geometry"] = args.link_geometry;
  AddWarnings(args.warnings, j);
}

// The JSON object of a plan (with --confirm: also simulated calibrations at
// the planned and the random poses).
nlohmann::json PlanJson(const PlanArgs& args, const Robot& robot,
                        const PlanResult& plan, bool with_rig) {
  nlohmann::json sigma = nlohmann::json::object();
  nlohmann::json random_sigma = nlohmann::json::object();
  for (size_t k = 0; k < plan.params.size(); ++k) {
    sigma[plan.params[k].name] = Number(plan.planned.sigma[k]);
    random_sigma[plan.params[k].name] = Number(plan.random.sigma[k]);
  }
  nlohmann::json j;
  j["n"] = plan.poses.size();
  j["out"] = args.out;
  j["mode"] = args.options.fixed_point ? "fixed_point" : "free";
  j["criterion"] = args.criterion;
  j["noise_mm"] = args.options.noise_mm;
  j["predicted_sigma"] = sigma;
  j["random_predicted_sigma"] = random_sigma;
  j["predicted_tip_rms_mm"] = Number(plan.planned.tip_rms_mm);
  j["random_predicted_tip_rms_mm"] = Number(plan.random.tip_rms_mm);
  j["sigma_gmean_over_bound"] = Number(plan.planned_sigma_gmean);
  j["random_sigma_gmean_over_bound"] = Number(plan.random_sigma_gmean);
  j["sigma_gain"] = Number(plan.random_sigma_gmean / plan.planned_sigma_gmean);
  j["log_det"] = Number(plan.planned.log_det);
  j["observability"] = {{"O1", Number(plan.planned.o1)},
                        {"O3", Number(plan.planned.o3)},
                        {"O4", Number(plan.planned.o4)}};
  j["random_observability"] = {{"O1", Number(plan.random.o1)},
                               {"O3", Number(plan.random.o3)},
                               {"O4", Number(plan.random.o4)}};
  j["random_log_det"] = Number(plan.random.log_det);
  j["coverage"] = {{"planned", CoverageJson(plan.planned_coverage)},
                   {"random", CoverageJson(plan.random_coverage)}};
  j["joint_travel"] = Number(plan.planned.joint_travel);
  j["random_joint_travel"] = Number(plan.random.joint_travel);
  j["unidentifiable"] = plan.unidentifiable;
  j["candidates"] = plan.feasible_candidates;
  j["draws"] = plan.draws;
  j["swaps"] = plan.swaps;
  j["limit_margin"] = args.options.limit_margin;
  j["link_radius_mm"] = args.options.safety.link_radius_mm;
  SafetyJson(args, &j);
  j["obstacles"] = args.obstacles;
  j["rejected_limits"] = plan.rejected_limits;
  j["rejected_collision"] = plan.rejected_collision;
  j["rejected_visibility"] = plan.rejected_visibility;
  j["collisions"] = plan.collisions;
  if (with_rig) {
    const Eigen::Vector3d w =
        RotationVectorFromMatrix(plan.rig_from_base.R) * 180 / M_PI;
    j["rig_from_base"] = {w.x(),
                          w.y(),
                          w.z(),
                          plan.rig_from_base.t.x(),
                          plan.rig_from_base.t.y(),
                          plan.rig_from_base.t.z()};
  }
  if (args.options.fixed_point) {
    const Eigen::Vector3d& p = plan.fixed_point_in_base;
    j["fixed_point_in_base"] = {p.x(), p.y(), p.z()};
  }
  if (args.confirm > 0) {
    ConfirmOptions co;
    co.repetitions = args.confirm;
    co.seed = args.options.seed;
    const ConfirmResult a =
        ConfirmDesign(robot, plan, plan.poses, args.options, co);
    const ConfirmResult b =
        ConfirmDesign(robot, plan, plan.random_poses, args.options, co);
    nlohmann::json err = nlohmann::json::object();
    nlohmann::json rerr = nlohmann::json::object();
    for (size_t k = 0; k < plan.params.size(); ++k) {
      err[plan.params[k].name] = Number(a.rms_error[k]);
      rerr[plan.params[k].name] = Number(b.rms_error[k]);
    }
    j["confirmed"] = {{"repetitions", args.confirm},
                      {"rms_error", err},
                      {"random_rms_error", rerr},
                      {"tip_rms_mm", Number(a.tip_rms_mm)},
                      {"random_tip_rms_mm", Number(b.tip_rms_mm)},
                      {"error_gain", Number(b.error_gmean / a.error_gmean)},
                      {"failed_fits", a.failed_fits + b.failed_fits}};
  }
  j["seconds"] = plan.seconds;
  return j;
}

// A 3-vector option (x,y,z) or nothing.
std::optional<Eigen::Vector3d> Vector3Option(const std::vector<double>& v) {
  if (v.empty()) return std::nullopt;
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Eigen::Vector3d RotationVectorDeg(const Eigen::Matrix3d& rotation) {
  return RotationVectorFromMatrix(rotation) * 180 / M_PI;
}

nlohmann::json Json3(const Eigen::Vector3d& v) {
  return {Number(v.x()), Number(v.y()), Number(v.z())};
}

// The JSON object of an ISO 9283 cube plan.
nlohmann::json IsoCubeJson(const PlanArgs& args, const Robot& robot,
                           const IsoCubePlan& plan) {
  nlohmann::json poses = nlohmann::json::array();
  for (const IsoCubePose& pose : plan.poses) {
    poses.push_back({{"pose", pose.label},
                     {"position_mm", Json3(pose.position_mm)},
                     {"joints", pose.joints}});
  }
  nlohmann::json order = nlohmann::json::array();
  for (int index : IsoCubeCycleOrder())
    order.push_back(plan.poses[index].label);
  nlohmann::json joint_names = nlohmann::json::array();
  for (const RobotRow& row : robot.joints) joint_names.push_back(row.name);
  nlohmann::json j;
  j["n"] = plan.rows.size();
  j["out"] = args.out;
  j["mode"] = "iso9283";
  j["cube_mm"] = plan.cube_mm;
  j["cube_center_mm"] = Json3(plan.center_mm);
  j["orientation_deg"] = plan.fixed_orientation
                             ? Json3(RotationVectorDeg(plan.rotation))
                             : nlohmann::json(nullptr);
  j["cycles"] = plan.cycles;
  j["cycle_order"] = order;
  j["joint_names"] = joint_names;
  j["poses"] = poses;
  j["limit_margin"] = args.cube.limit_margin;
  j["link_radius_mm"] = args.cube.safety.link_radius_mm;
  SafetyJson(args, &j);
  j["obstacles"] = args.obstacles;
  j["seeds_tried"] = plan.seeds_tried;
  j["draws"] = plan.draws;
  j["seconds"] = plan.seconds;
  return j;
}

int RunIsoCube(PlanArgs args, const Robot& robot) {
  if (!args.design_only.empty()) {
    std::string names;
    for (const std::string& name : args.design_only) {
      names += (names.empty() ? "" : ", ") + name;
    }
    throw InputError("--iso9283 plans the standard's five poses: " + names +
                     " belong to a calibration design and are not used");
  }
  IsoCubeOptions& cube = args.cube;
  cube.center_mm = Vector3Option(args.cube_center);
  cube.orientation_deg = Vector3Option(args.orientation);
  cube.limit_margin = args.options.limit_margin;
  cube.seed = args.options.seed;
  cube.safety = args.options.safety;
  const IsoCubePlan plan = PlanIsoCube(robot, cube);
  WriteFileAtomic(args.out, FormatIsoCubeCsv(robot, plan));
  if (args.json) {
    PrintJson(IsoCubeJson(args, robot, plan));
    return 0;
  }
  std::printf(
      "kincal plan: ISO 9283 cube %.6g mm centred at (%.1f, %.1f, %.1f) mm, "
      "%d cycles of P5 P4 P3 P2 P1: %zu rows -> %s\n",
      plan.cube_mm, plan.center_mm.x(), plan.center_mm.y(), plan.center_mm.z(),
      plan.cycles, plan.rows.size(), args.out.c_str());
  if (plan.fixed_orientation) {
    const Eigen::Vector3d w = RotationVectorDeg(plan.rotation);
    std::printf("  tool orientation (rotation vector) %.3f %.3f %.3f deg\n",
                w.x(), w.y(), w.z());
  }
  for (const IsoCubePose& pose : plan.poses) {
    std::printf("  %s  (%9.3f, %9.3f, %9.3f) mm  joints", pose.label.c_str(),
                pose.position_mm.x(), pose.position_mm.y(),
                pose.position_mm.z());
    for (double q : pose.joints) std::printf(" %.4f", q);
    std::printf("\n");
  }
  return 0;
}

int RunPlan(PlanArgs args) {
  const Robot robot = ReadRobot(args.robot, args.root, args.tip);
  if (!args.obstacles.empty()) {
    args.options.safety.obstacles = ReadObstaclesYaml(args.obstacles);
  }
  args.options.safety.self_collision = !args.no_self_collision;
  UseUrdfCollisionGeometry(robot, &args);
  if (args.iso9283) return RunIsoCube(args, robot);
  if (!args.n_given) {
    throw InputError(
        "--n is required (or --iso9283 --cube MM for the ISO "
        "9283 test poses)");
  }
  if (args.cube_option_given) {
    throw InputError(
        "--cube, --cycles, --cube-center and --orientation go with --iso9283");
  }
  if (args.rig.empty() != args.target.empty()) {
    throw InputError("--rig and --target go together");
  }
  std::optional<Rig> rig;
  std::optional<Target> target;
  if (!args.rig.empty()) {
    rig = ReadRigYaml(args.rig);
    target = ReadTargetYaml(args.target);
    args.options.rig = &*rig;
    args.options.target = &*target;
  }
  if (!args.rig_from_base.empty()) {
    if (args.rig_from_base.size() != 6 || args.rig.empty()) {
      throw InputError(
          "--rig-from-base: expected 6 numbers (rotation vector in deg, "
          "translation in mm) together with --rig");
    }
    const Eigen::Vector3d w(args.rig_from_base[0], args.rig_from_base[1],
                            args.rig_from_base[2]);
    Rigid3 r;
    r.R = RotationMatrixFromVector(w * M_PI / 180);
    r.t = Eigen::Vector3d(args.rig_from_base[3], args.rig_from_base[4],
                          args.rig_from_base[5]);
    args.options.rig_from_base = r;
  }
  if (args.criterion == "d") {
    args.options.criterion = PlanOptions::kDOptimal;
  } else if (args.criterion == "sigma") {
    args.options.criterion = PlanOptions::kSigma;
  } else if (args.criterion == "coverage") {
    args.options.criterion = PlanOptions::kCoverage;
  } else {
    throw InputError("--criterion: expected 'd', 'sigma' or 'coverage', got '" +
                     args.criterion + "'");
  }
  Progress progress("kincal plan", args.json);
  args.options.progress = [&progress](const std::string& what) {
    progress.Stage(what);
  };
  const PlanResult plan = PlanPoses(robot, args.options);
  progress.Done();
  AddCoverageWarnings(plan, &args);
  WriteFileAtomic(args.out, FormatPosesCsv(robot, plan.poses));
  if (!args.random_out.empty()) {
    WriteFileAtomic(args.random_out, FormatPosesCsv(robot, plan.random_poses));
  }
  if (args.json) {
    PrintJson(PlanJson(args, robot, plan, rig.has_value()));
    return 0;
  }
  std::printf("kincal plan: %zu poses -> %s (%s, %d feasible candidates)\n",
              plan.poses.size(), args.out.c_str(),
              args.options.fixed_point ? "fixed point" : "free",
              plan.feasible_candidates);
  std::printf("  %-24s %12s %12s\n", "parameter", "planned", "random");
  for (size_t k = 0; k < plan.params.size(); ++k) {
    std::printf("  %-24s %12.5f %12.5f %s\n", plan.params[k].name.c_str(),
                plan.planned.sigma[k], plan.random.sigma[k],
                plan.params[k].angle ? "deg" : "mm");
  }
  std::printf(
      "  rejected draws: %ld outside the limits minus %.3g of the "
      "range, %ld for collisions, %ld with too few tags visible\n",
      plan.rejected_limits, args.options.limit_margin, plan.rejected_collision,
      plan.rejected_visibility);
  std::printf("  predicted tip RMS %.4f mm (random poses: %.4f mm)\n",
              plan.planned.tip_rms_mm, plan.random.tip_rms_mm);
  std::printf(
      "  sigma geometric mean %.3gx smaller than random; joint travel "
      "%.2f (random %.2f)\n",
      plan.random_sigma_gmean / plan.planned_sigma_gmean,
      plan.planned.joint_travel, plan.random.joint_travel);
  std::printf("  travel coverage, largest gap without a reading (random):\n");
  for (size_t j = 0; j < plan.planned_coverage.size(); ++j) {
    const JointCoverage& c = plan.planned_coverage[j];
    std::printf("    %-24s %8.2f of %.6g%s (%.2f)%s\n", c.joint.c_str(),
                c.Gap(), c.hi - c.lo, c.circular ? " (one turn)" : "",
                plan.random_coverage[j].Gap(), c.wide ? "  wide" : "");
  }
  return 0;
}

}  // namespace

void AddPlanCommand(CLI::App& app, Runner* run) {
  auto args = std::make_shared<PlanArgs>();
  CLI::App* sub = app.add_subcommand(
      "plan",
      "Choose N robot poses that best determine the identifiable parameters "
      "(D-optimal design within joint limits, tags visible when a rig is "
      "given), ordered for short joint motions");
  AddRobotOptions(sub, &args->robot, &args->root, &args->tip,
                  "robot.yaml or .urdf with limits")
      ->required();
  sub->add_option("--n", args->options.n,
                  "number of poses (required without --iso9283)");
  sub->add_option("--out", args->out, "POSES.csv to write")->required();
  sub->add_option("--random-out", args->random_out,
                  "also write the N random feasible poses it compares with");
  sub->add_option("--rig", args->rig, "rig.yaml (visibility constraint)");
  sub->add_option("--target", args->target, "target.yaml (with --rig)");
  sub->add_option("--rig-from-base", args->rig_from_base,
                  "pose of the robot base in the rig: rx ry rz (rotation "
                  "vector, deg) tx ty tz (mm); default: the rig is placed "
                  "looking at the tags")
      ->expected(6);
  sub->add_option("--seed", args->options.seed, "random seed");
  sub->add_option("--candidates", args->options.candidates,
                  "feasible random candidate poses to choose from")
      ->check(CLI::Range(2, 100000));
  sub->add_option("--noise-mm", args->options.noise_mm,
                  "measurement noise per coordinate, for the predictions")
      ->check(CLI::PositiveNumber);
  sub->add_flag("--fixed-point", args->options.fixed_point,
                "the seed's experiment: tip held at one point, orientations "
                "varied");
  sub->add_option("--min-tags", args->options.min_tags,
                  "tags that must be visible in both cameras")
      ->check(CLI::Range(1, 1000));
  sub->add_option("--max-obliquity", args->options.max_obliquity_deg,
                  "largest angle between a tag's normal and the view ray, deg")
      ->check(CLI::Range(1.0, 89.0));
  sub->add_option("--criterion", args->criterion,
                  "sigma: minimise the product of the robot parameters' "
                  "predicted sigmas; d: D-optimal (log det); coverage: a "
                  "campaign for diagnose model, every joint's readings "
                  "spread over its travel");
  sub->add_option("--extreme", args->options.extreme_fraction,
                  "probability that a candidate puts a joint at a limit")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--limit-margin", args->options.limit_margin,
                  "keep every pose this fraction of each joint's range away "
                  "from both limits (extreme candidates go to the limit minus "
                  "the margin)")
      ->check(CLI::Range(0.0, 0.45));
  sub->add_option("--obstacles", args->obstacles,
                  "OBST.yaml: planes and boxes in the base frame "
                  "(kincal_obstacles: 1; docs/LAB.md); poses where a link "
                  "capsule meets one are rejected")
      ->check(CLI::ExistingFile);
  sub->add_option("--link-radius", args->options.safety.link_radius_mm,
                  "radius of the capsules around the links (segments between "
                  "the joint frames' origins, and the tool to the tip), mm")
      ->check(CLI::Range(0.0, 1000.0));
  sub->add_flag("--no-self-collision", args->no_self_collision,
                "do not reject poses where two non-adjacent link capsules "
                "meet");
  sub->add_option("--confirm", args->confirm,
                  "also simulate this many sessions at the planned and at the "
                  "random poses, calibrate them and report the actual errors")
      ->check(CLI::Range(0, 1000));
  sub->add_flag("--iso9283", args->iso9283,
                "plan ISO 9283's pose-accuracy test instead: P1..P5 on the "
                "diagonal plane of a cube of edge --cube, one tool "
                "orientation, --cycles cycles of P5 P4 P3 P2 P1 "
                "(docs/PLAN.md)");
  sub->add_option("--cube", args->cube.cube_mm,
                  "with --iso9283: the cube's edge length, mm")
      ->check(CLI::PositiveNumber);
  sub->add_option("--cycles", args->cube.cycles,
                  "with --iso9283: cycles of the five poses (the standard's "
                  "30)")
      ->check(CLI::Range(1, 10000));
  sub->add_option("--cube-center", args->cube_center,
                  "with --iso9283: the cube's centre X,Y,Z in the base "
                  "frame, mm; default: the middle of the reachable workspace")
      ->expected(3)
      ->delimiter(',');
  sub->add_option("--orientation", args->orientation,
                  "with --iso9283, arms with 6+ joints: the tool orientation "
                  "rx,ry,rz (rotation vector of base_from_tip, deg); default: "
                  "that of the seed configuration")
      ->expected(3)
      ->delimiter(',');
  sub->add_flag("--json", args->json, "print one JSON object");
  sub->footer(HelpFooter(
      "Example (60 poses for a UR10 seen by a stereo rig, and the gain over 60 "
      "random poses confirmed on simulated sessions):\n  kincal plan --robot "
      "data/robots/ur10.yaml --n 60 --rig rig.yaml --target target.yaml --out "
      "poses.csv --random-out random.csv --confirm 5 --json",
      "; poses.csv in the robot's joint units (deg | mm)"));
  sub->callback([run, args, sub] {
    args->n_given = sub->count("--n") > 0;
    for (const char* name :
         {"--cube", "--cycles", "--cube-center", "--orientation"}) {
      args->cube_option_given = args->cube_option_given || sub->count(name);
    }
    for (const char* name :
         {"--n", "--random-out", "--rig", "--target", "--rig-from-base",
          "--candidates", "--noise-mm", "--fixed-point", "--min-tags",
          "--max-obliquity", "--criterion", "--extreme", "--confirm"}) {
      if (sub->count(name) > 0) args->design_only.push_back(name);
    }
    *run = [args] { return RunPlan(*args); };
  });
}

}  // namespace kincal::app
