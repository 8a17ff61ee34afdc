// obsgroup: group robot observations into consistent local maps and a
// metric-topological map (Blanco, Gonzalez, Fernandez-Madrigal, ICRA 2006).
//
// Exit codes: 0 done, 2 usage error, 3 input error, 130 interrupted (SIGINT
// or SIGTERM: the output folder is left as it was), 1 anything else.

#include "errors.h"
#include "partition_command.h"

#include <CLI/CLI.hpp>
#include <pcl/console/print.h>

#include <signal.h>

#include <cstdio>
#include <map>

namespace {

obsgroup::InterruptFlag interrupt_requested{false};
static_assert(obsgroup::InterruptFlag::is_always_lock_free, "a signal handler may only touch lock-free atomics");

extern "C" void onInterrupt(int) { interrupt_requested.store(true); }

/// The first Ctrl-C asks the run to stop cleanly (it polls the flag); the
/// handler is then reset, so a second one ends the process at once.
void catchInterrupts() {
  struct sigaction action {};
  action.sa_handler = onInterrupt;
  action.sa_flags = SA_RESETHAND;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

void addPartitionOptions(CLI::App& command, obsgroup::cli::PartitionArgs& args, double& fov, double& max_range,
                         std::string& poses, int& max_depth, double& map_voxel, std::vector<double>& band, bool& paper) {
  using obsgroup::SplitCriterion;
  using obsgroup::io::LaserSource;
  using obsgroup::io::PoseFormat;
  command.add_option("input", args.input,
                     "CARMEN log (.clf, .log, .gfs.log, gzipped or not; - reads standard input) or folder of .pcd files")
      ->required();
  command.add_option("-o,--output", args.output, "folder to write the results to")->required();
  command.add_option("--format", args.format, "input format (default: from the input)")
      ->check(CLI::IsMember({"auto", "carmen", "pcd"}));

  const std::map<std::string, LaserSource> lasers{
      {"front", LaserSource::Front}, {"rear", LaserSource::Rear}, {"robotlaser", LaserSource::RobotLaser}};
  command.add_option("--laser", args.laser, "CARMEN: which laser messages (FLASER, RLASER, ROBOTLASER1)")
      ->transform(CLI::CheckedTransformer(lasers))
      ->group("CARMEN logs");
  command.add_option("--fov", fov, "CARMEN: field of view of FLASER/RLASER scans, degrees (default: PARAM, else 180)")
      ->check(CLI::Range(1.0, 360.0))
      ->group("CARMEN logs");
  command.add_option("--max-range", max_range, "CARMEN: readings at or beyond this are no return, metres")
      ->check(CLI::PositiveNumber)
      ->group("CARMEN logs");
  command.add_flag("--skip-bad-lines", args.skip_bad_lines,
                   "CARMEN: skip malformed lines (a truncated last line, say), counted in one warning")
      ->group("CARMEN logs");

  command.add_option("--poses", poses, "PCD: poses file, one line per cloud (default: each PCD's VIEWPOINT)")
      ->group("PCD sequences");
  const std::map<std::string, PoseFormat> formats{{"tum", PoseFormat::Tum}, {"kitti", PoseFormat::Kitti}};
  command.add_option("--pose-format", args.pose_format, "PCD: format of --poses")
      ->transform(CLI::CheckedTransformer(formats))
      ->group("PCD sequences");

  const std::map<std::string, obsgroup::SensedSpaceModel> models{
      {"points", obsgroup::SensedSpaceModel::Points},
      {"free-space", obsgroup::SensedSpaceModel::FreeSpace},
      {"visibility", obsgroup::SensedSpaceModel::Visibility}};
  command.add_option("--sso", args.sso,
                     "sensed-space model: points (eq. 16-18, the paper's), free-space (cells the beams cross) or "
                     "visibility (cells visible from the pose; the default)")
      ->transform(CLI::CheckedTransformer(models))
      ->group("Method");
  command.add_flag("--paper", paper,
                   "the paper's method exactly: --sso points --split mean --ncut-threshold 1 (delta as given)")
      ->group("Method");
  command.add_option("--cell", args.region.cell_size, "free-space, visibility: grid cell (voxel in 3D), metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group("Method");
  command.add_option("--range", args.region.max_range, "free-space, visibility: how far from the sensor, metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group("Method");
  command.add_option("--clearance", args.region.clearance,
                     "visibility: occupied cells nearer the pose than this do not block, metres")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str()
      ->group("Method");
  command.add_option("--min-observations", args.region.min_observations,
                     "visibility: a cell is occupied when this many observations have a point in it (and no more "
                 "saw through it)")
      ->check(CLI::Range(1, 1 << 30))
      ->capture_default_str()
      ->group("Method");
  command.add_option("--band", band, "visibility, 3D: heights above the sensor that make the occupancy grid, "
                                     "LOW HIGH metres")
      ->expected(2)
      ->group("Method");
  command.add_option("--delta", args.delta, "points: match distance of eq. (16), metres")
      ->check(CLI::PositiveNumber)
      ->capture_default_str()
      ->group("Method");
  command.add_option("--voxel", args.voxel, "voxel downsampling leaf before matching, metres (0 = off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str()
      ->group("Method");
  command.add_option("--ncut-threshold", args.ncut_threshold, "accept a bisection while Ncut < this (sec. II-B)")
      ->check(CLI::Range(0.0, 2.0))
      ->capture_default_str()
      ->group("Method");
  const std::map<std::string, SplitCriterion> splits{
      {"mean", SplitCriterion::Mean}, {"sign", SplitCriterion::Sign}, {"best", SplitCriterion::BestNcut}};
  command.add_option("--split", args.split, "how the eigenvector is cut: best (smallest Ncut; the default), mean (the paper's) or sign")
      ->transform(CLI::CheckedTransformer(splits))
      ->group("Method");
  command.add_option("--min-group-size", args.min_group_size, "reject a bisection giving a smaller group")
      ->check(CLI::Range(1, 1 << 30))
      ->capture_default_str()
      ->group("Method");
  command.add_option("--max-depth", max_depth, "do not bisect deeper than this (default: no limit)")
      ->check(CLI::NonNegativeNumber)
      ->group("Method");
  command.add_option("--threads", args.threads, "threads (0 = all cores); results do not depend on it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  const std::map<std::string, obsgroup::Refinement> refinements{{"none", obsgroup::Refinement::None},
                                                                {"icp", obsgroup::Refinement::Icp},
                                                                {"lum", obsgroup::Refinement::Lum}};
  command.add_option("--refine", args.refine,
                     "align each local map's observations: none, icp (spanning tree) or lum (Lu & Milios)")
      ->transform(CLI::CheckedTransformer(refinements));
  command.add_option("--map-voxel", map_voxel, "voxel leaf of the local maps written, metres (default: delta/2)")
      ->check(CLI::NonNegativeNumber);
  command.add_flag("--force", args.force, "replace the results already in the output folder");
  command.add_flag("-q,--quiet", args.quiet, "no progress bar, summary or warnings on stderr");
  command.add_flag("!--no-pictures", args.pictures,
                   "do not draw map.png/.svg, weights.png, fiedler.png, local_maps/group_NNN.png");
}

}  // namespace

int main(int argc, char** argv) {
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // obsgroup words its own errors

  CLI::App app{"obsgroup: group robot observations into consistent local maps and a metric-topological map"};
  app.set_version_flag("--version", "obsgroup 0.1.0");
  app.require_subcommand(1, 1);
  obsgroup::cli::PartitionArgs args;
  double fov = 0.0, max_range = 0.0, map_voxel = 0.0;
  std::string poses;
  int max_depth = 0;
  std::vector<double> band;
  bool paper = false;
  CLI::App* partition = app.add_subcommand("partition", "group the observations of a log or a PCD sequence");
  addPartitionOptions(*partition, args, fov, max_range, poses, max_depth, map_voxel, band, paper);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  if (partition->count("--fov")) args.field_of_view_deg = fov;
  if (partition->count("--max-range")) args.max_range = max_range;
  if (partition->count("--poses")) args.poses = poses;
  if (partition->count("--pose-format") && !args.poses) {
    std::fprintf(stderr, "obsgroup: error: --pose-format applies to a --poses file (PCD sequences)\n");
    return 2;
  }
  if (partition->count("--max-depth")) args.max_depth = max_depth;
  if (partition->count("--map-voxel")) args.map_voxel = map_voxel;
  // Options of one model given with another are a mistake, not a no-op.
  const auto usage = [](const std::string& message) {
    std::fprintf(stderr, "obsgroup: error: %s\n", message.c_str());
    return 2;
  };
  if (paper) {
    if (partition->count("--sso") && args.sso != obsgroup::SensedSpaceModel::Points)
      return usage("--paper uses --sso points; drop one of them");
    if (partition->count("--split") && args.split != obsgroup::SplitCriterion::Mean)
      return usage("--paper uses --split mean; drop one of them");
    if (partition->count("--ncut-threshold") && args.ncut_threshold != 1.0)
      return usage("--paper uses --ncut-threshold 1; drop one of them");
    args.sso = obsgroup::SensedSpaceModel::Points;
    args.split = obsgroup::SplitCriterion::Mean;
    args.ncut_threshold = 1.0;
  }
  const bool points = args.sso == obsgroup::SensedSpaceModel::Points;
  for (const char* option : {"--cell", "--range", "--clearance", "--min-observations", "--band"})
    if (points && partition->count(option))
      return usage(std::string(option) + " applies to --sso free-space or visibility, not points");
  if (!points && partition->count("--delta"))
    return usage("--delta applies to --sso points (the region models use --cell)");
  if (args.sso == obsgroup::SensedSpaceModel::FreeSpace)
    for (const char* option : {"--clearance", "--min-observations", "--band"})
      if (partition->count(option)) return usage(std::string(option) + " applies to --sso visibility only");
  if (partition->count("--band")) {
    if (!(band[0] < band[1])) {
      std::fprintf(stderr, "obsgroup: error: --band: LOW must be below HIGH (got %g %g)\n", band[0], band[1]);
      return 2;
    }
    args.region.band_low = band[0];
    args.region.band_high = band[1];
  }

  args.interrupt = &interrupt_requested;
  catchInterrupts();
  try {
    return obsgroup::cli::runPartition(args);
  } catch (const obsgroup::Interrupted&) {
    std::fprintf(stderr, "\nobsgroup: interrupted; %s was left as it was\n", args.output.c_str());
    return 130;
  } catch (const obsgroup::io::UsageError& e) {
    std::fprintf(stderr, "obsgroup: error: %s\n", e.what());
    return 2;
  } catch (const obsgroup::io::InputError& e) {
    std::fprintf(stderr, "obsgroup: error: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "obsgroup: error: %s\n", e.what());
    return 1;
  }
}
