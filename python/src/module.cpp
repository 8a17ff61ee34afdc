// obsgroup._obsgroup: the C++ library behind the Python module `obsgroup`.
// Options arrive as the command's own arguments (the Python layer turns
// keyword arguments into them), so defaults, checks and messages are the
// command's. Points cross as numpy views of the PCL clouds where the layout
// allows; every long call runs with the GIL released, stops on Ctrl-C and
// hands progress to a Python callback one step at a time.

#include "command_line.h"
#include "partition_command.h"
#include "place_outputs.h"

#include <obsgroup/common/interrupt.h>
#include <obsgroup/common/invalid_observation.h>
#include <obsgroup/io/errors.h>
#include <obsgroup/maps/local_map_builder.h>
#include <obsgroup/maps/odometry_correction.h>
#include <obsgroup/maps/topological_map.h>
#include <obsgroup/observation_grouping.h>
#include <obsgroup/online_grouping.h>
#include <obsgroup/places/place_map.h>

#include <pcl/common/io.h>
#include <pcl/console/print.h>

#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <signal.h>

#include <atomic>
#include <functional>
#include <chrono>
#include <mutex>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace py = pybind11;

namespace obsgroup::python {
namespace {

using CloudXYZ = pcl::PointCloud<pcl::PointXYZ>;
using AnyCloud = std::variant<CloudXYZ::ConstPtr, pcl::PointCloud<pcl::PointXYZI>::ConstPtr,
                              pcl::PointCloud<pcl::PointXYZRGB>::ConstPtr>;

/// One observation: a cloud in the sensor frame (the point type the input
/// carries, shared, never copied), its pose and where it came from.
struct PyObservation {
  AnyCloud cloud;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::optional<double> stamp;
  std::string source;

  std::size_t size() const {
    return std::visit([](const auto& c) { return c ? c->size() : std::size_t(0); }, cloud);
  }
  /// The cloud as PointXYZ: shared when it is one, else its xyz copied.
  CloudXYZ::ConstPtr xyz() const {
    if (const auto* shared = std::get_if<CloudXYZ::ConstPtr>(&cloud)) return *shared;
    auto copy = std::make_shared<CloudXYZ>();
    std::visit([&copy](const auto& c) { pcl::copyPointCloud(*c, *copy); }, cloud);
    return copy;
  }
  std::string pointType() const {
    switch (cloud.index()) {
      case 1: return "xyzi";
      case 2: return "xyzrgb";
      default: return "xyz";
    }
  }
};

// --- the command's arguments ---

std::vector<const char*> argvOf(const std::vector<std::string>& words) {
  std::vector<const char*> argv{"obsgroup"};
  for (const auto& w : words) argv.push_back(w.c_str());
  return argv;
}

/// `obsgroup WORDS...` parsed; a usage error raises UsageError.
cli::PartitionArgs parseArgs(const std::vector<std::string>& words) {
  const std::vector<const char*> argv = argvOf(words);
  const cli::ParsedCommandLine parsed = cli::parseCommandLine(int(argv.size()), argv.data());
  if (!parsed.args) throw io::UsageError(parsed.error.empty() ? "nothing to run" : parsed.error);
  return *parsed.args;
}

// --- long calls: GIL released, Ctrl-C and progress polled ---

/// Progress for a Python callback. The steps come from the threads doing the
/// work; each is handed to the callback with the GIL, one at a time. If the
/// callback raises, the work is stopped (its interrupt flag) and the error kept
/// for the caller to raise.
class ProgressRelay {
 public:
  ProgressRelay(py::object callback, InterruptFlag& flag) : callback_(std::move(callback)), flag_(flag) {}
  ~ProgressRelay() {
    py::gil_scoped_acquire gil;  // the callback and a kept error are Python objects
    callback_ = py::none();
    error_.reset();
  }
  void operator()(const std::string& stage, std::size_t done, std::size_t total) {
    if (callback_.is_none() || failed_.load()) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (failed_.load()) return;
    py::gil_scoped_acquire gil;
    try {
      callback_(stage, done, total);
    } catch (py::error_already_set& e) {
      error_.emplace(std::move(e));
      failed_.store(true);
      flag_.store(true);
    }
  }
  /// The callback's error, if it raised (with the GIL).
  void rethrow() {
    if (error_) {
      py::error_already_set error = std::move(*error_);
      error_.reset();
      throw error;
    }
  }

 private:
  py::object callback_;
  InterruptFlag& flag_;
  std::mutex mutex_;
  std::atomic<bool> failed_{false};
  std::optional<py::error_already_set> error_;
};

/// While a long call runs, SIGINT (Ctrl-C) sets the call's interrupt flag, so
/// that the work stops at its next poll, then goes on to Python's own handler,
/// which raises KeyboardInterrupt when the call returns. Installed only on
/// Python's main thread (where its handlers run) and only over a handler
/// Python installed, so a program that ignores SIGINT or leaves it to the
/// system keeps its choice.
class SigintToFlag {
 public:
  explicit SigintToFlag(InterruptFlag& flag) {
    if (PyThread_get_thread_ident() != mainThread()) return;
    struct sigaction current {};
    if (sigaction(SIGINT, nullptr, &current) != 0 || (current.sa_flags & SA_SIGINFO) ||
        current.sa_handler == SIG_DFL || current.sa_handler == SIG_IGN || current.sa_handler == &onSignal)
      return;
    previous_ = current;
    flag_.store(&flag);
    struct sigaction action {};
    action.sa_handler = &onSignal;
    sigemptyset(&action.sa_mask);
    installed_ = sigaction(SIGINT, &action, nullptr) == 0;
  }
  ~SigintToFlag() {
    if (!installed_) return;
    sigaction(SIGINT, &previous_, nullptr);
    flag_.store(nullptr);
  }
  SigintToFlag(const SigintToFlag&) = delete;
  SigintToFlag& operator=(const SigintToFlag&) = delete;

 private:
  static unsigned long mainThread() {
    static const unsigned long ident = py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
    return ident;
  }
  static void onSignal(int signal) {
    if (InterruptFlag* flag = flag_.load()) flag->store(true);
    if (previous_.sa_handler != SIG_DFL && previous_.sa_handler != SIG_IGN) previous_.sa_handler(signal);
  }
  static inline std::atomic<InterruptFlag*> flag_{nullptr};
  static inline struct sigaction previous_ {};
  bool installed_ = false;
};

/// Runs `work` on this thread with the GIL released (the readers and the
/// grouping keep their own threads busy; the caller's other Python threads
/// run meanwhile). Ctrl-C stops it through `flag` and raises KeyboardInterrupt;
/// an error of the progress callback stops it and is raised.
template <typename Work>
auto runReleased(Work work, InterruptFlag& flag, ProgressRelay* progress = nullptr) {
  using Result = decltype(work());
  flag.store(false);
  std::optional<Result> result;
  std::exception_ptr failure;
  {
    SigintToFlag sigint(flag);
    py::gil_scoped_release release;
    try {
      result.emplace(work());
    } catch (...) {
      failure = std::current_exception();
    }
  }
  if (progress) progress->rethrow();
  // Ctrl-C: Python's handler raises KeyboardInterrupt now (or what a handler of the program's raises);
  // should none raise, the work's Interrupted is translated to KeyboardInterrupt.
  if (flag.load() && PyErr_CheckSignals() != 0) throw py::error_already_set();
  if (failure) std::rethrow_exception(failure);
  return std::move(*result);
}

// --- numpy ---

/// An (n, 3) float32 view of a cloud's xyz: no copy, the array keeps the
/// cloud alive, read-only (the cloud may be shared).
template <typename PointT>
py::array xyzView(const typename pcl::PointCloud<PointT>::ConstPtr& cloud) {
  static_assert(offsetof(PointT, x) == 0 && offsetof(PointT, y) == 4 && offsetof(PointT, z) == 8);
  auto* keep = new typename pcl::PointCloud<PointT>::ConstPtr(cloud);
  py::capsule owner(keep, [](void* p) { delete static_cast<typename pcl::PointCloud<PointT>::ConstPtr*>(p); });
  const float* data = cloud->empty() ? nullptr : &cloud->points[0].x;
  py::array_t<float> view({py::ssize_t(cloud->size()), py::ssize_t(3)},
                          {py::ssize_t(sizeof(PointT)), py::ssize_t(sizeof(float))}, data, owner);
  py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return std::move(view);
}

py::array pointsOf(const AnyCloud& cloud) {
  return std::visit([](const auto& c) -> py::array {
    using Cloud = typename std::decay_t<decltype(c)>::element_type;
    return xyzView<typename std::remove_const_t<Cloud>::PointType>(c);
  }, cloud);
}

/// Points from numpy: (n, 2) or (n, 3), any real dtype, copied once into a
/// PointXYZ cloud (2D points get z = 0).
CloudXYZ::Ptr cloudOf(const py::array_t<float, py::array::c_style | py::array::forcecast>& points) {
  if (points.ndim() != 2 || (points.shape(1) != 2 && points.shape(1) != 3))
    throw py::value_error("points must be an (n, 2) or (n, 3) array; got shape " +
                          std::string(py::str(py::getattr(points, "shape"))));
  const py::ssize_t n = points.shape(0), columns = points.shape(1);
  auto cloud = std::make_shared<CloudXYZ>();
  cloud->resize(std::size_t(n));
  const float* in = points.data();
  for (py::ssize_t i = 0; i < n; ++i) {
    auto& p = (*cloud)[std::size_t(i)];
    p.x = in[i * columns];
    p.y = in[i * columns + 1];
    p.z = columns == 3 ? in[i * columns + 2] : 0.0f;
  }
  return cloud;
}

Eigen::Isometry3d isometryOf(const Eigen::Matrix4d& matrix) {
  if (!matrix.allFinite()) throw py::value_error("pose: not finite");
  if (!matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)))
    throw py::value_error("pose: the last row of a 4x4 pose must be [0, 0, 0, 1]");
  const Eigen::Matrix3d R = matrix.topLeftCorner<3, 3>();
  if (!(R.transpose() * R).isIdentity(1e-6) || R.determinant() < 0)
    throw py::value_error("pose: the rotation part is not a rotation (orthonormal, determinant 1)");
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.matrix() = matrix;
  return pose;
}

py::array intArray(const std::vector<int>& values) {
  py::array_t<std::int64_t> out(py::ssize_t(values.size()));
  auto w = out.mutable_unchecked<1>();
  for (std::size_t i = 0; i < values.size(); ++i) w(py::ssize_t(i)) = values[i];
  return std::move(out);
}

/// W as coordinate arrays (rows, cols, values) of every stored entry.
py::tuple weightArrays(const WeightMatrix& W) {
  const auto nnz = py::ssize_t(W.nonZeros());
  py::array_t<std::int64_t> rows(nnz), cols(nnz);
  py::array_t<double> values(nnz);
  auto r = rows.mutable_unchecked<1>();
  auto c = cols.mutable_unchecked<1>();
  auto v = values.mutable_unchecked<1>();
  py::ssize_t k = 0;
  for (int j = 0; j < W.outerSize(); ++j)
    for (WeightMatrix::InnerIterator it(W, j); it; ++it, ++k) {
      r(k) = it.row();
      c(k) = it.col();
      v(k) = it.value();
    }
  return py::make_tuple(rows, cols, values, W.rows());
}

// --- results ---

struct PyPartition {
  Partition partition;
  WeightMatrix W;
  std::vector<std::string> warnings;
};

py::list splitsOf(const Partition& partition) {
  py::list out;
  for (const SplitNode& node : partition.splits) {
    py::dict d;
    d["members"] = node.members;
    d["kind"] = toString(node.kind);
    d["outcome"] = toString(node.outcome);
    d["accepted"] = node.accepted;
    d["ncut"] = node.ncut;
    d["threshold"] = node.threshold;
    d["eigenvalue"] = node.eigenvalue;
    d["children"] = node.children;
    out.append(d);
  }
  return out;
}

py::dict changeOf(const GroupChange& change) {
  py::dict d;
  d["kind"] = toString(change.kind);
  d["place"] = change.group;
  d["related"] = change.related;
  d["members"] = change.members;
  return d;
}

// --- reading ---

py::list observationsOf(cli::AnyInput&& input, std::vector<std::string>& warnings, std::string& format,
                        std::string& parameters) {
  py::list out;
  std::visit([&](auto&& read) {
    const auto& labels = read.input.labels;
    const auto& stamps = read.input.stamps;
    for (std::size_t i = 0; i < read.observations.size(); ++i) {
      PyObservation o;
      o.cloud = AnyCloud(typename std::decay_t<decltype(read.observations[i].cloud)>(read.observations[i].cloud));
      o.pose = read.observations[i].pose;
      if (i < stamps.size()) o.stamp = stamps[i];
      if (i < labels.size()) o.source = labels[i];
      out.append(std::move(o));
    }
    warnings = read.input.warnings;
    format = read.input.format;
    parameters = read.input.parameters.dump();
  }, input);
  return out;
}

py::tuple readInput(const std::vector<std::string>& words, const py::object& callback) {
  cli::PartitionArgs args = parseArgs(words);
  InterruptFlag flag{false};
  args.interrupt = &flag;
  ProgressRelay progress(callback, flag);
  args.progress = std::ref(progress);
  cli::AnyInput input = runReleased([&args] { return cli::readInput(args); }, flag, &progress);
  std::vector<std::string> warnings;
  std::string format, parameters;
  py::list observations = observationsOf(std::move(input), warnings, format, parameters);
  return py::make_tuple(observations, warnings, format, parameters);
}

// --- batch grouping ---

/// Held while an object computes with the GIL released: another Python
/// thread that calls into the same object meanwhile gets an error, not a race.
class BusyGuard {
 public:
  BusyGuard(std::mutex& mutex, const char* what) : lock_(mutex, std::try_to_lock) {
    if (!lock_.owns_lock())
      throw std::runtime_error(std::string(what) + " is busy in another thread; use one object per thread");
  }

 private:
  std::unique_lock<std::mutex> lock_;
};

class PyGrouping {
 public:
  explicit PyGrouping(const std::vector<std::string>& words) : args_(parseArgs(words)) {
    grouping_.setParameters(args_.method);
    grouping_.setInterruptFlag(&interrupt_);
  }
  int add(const PyObservation& observation) {
    BusyGuard busy(busy_, "the Grouping");
    grouping_.addObservation(observation.xyz(), observation.pose);
    return int(grouping_.getObservations().size()) - 1;
  }
  int addPoints(const py::array_t<float, py::array::c_style | py::array::forcecast>& points,
                const Eigen::Matrix4d& pose) {
    BusyGuard busy(busy_, "the Grouping");
    grouping_.addObservation(cloudOf(points), isometryOf(pose));
    return int(grouping_.getObservations().size()) - 1;
  }
  std::size_t size() const { return grouping_.getObservations().size(); }

  PyPartition compute(const py::object& callback) {
    BusyGuard busy(busy_, "the Grouping");
    ProgressRelay progress(callback, interrupt_);
    grouping_.setProgressCallback([&progress](std::size_t done, std::size_t total) { progress("overlap", done, total); });
    PyPartition result;
    result.partition = runReleased(
        [this] {
          Partition partition = grouping_.compute();
          // As the command does after the grouping.
          joinGroupsThroughPassages(grouping_.getObservations(), grouping_.getParameters(), partition);
          return partition;
        },
        interrupt_, &progress);
    grouping_.setProgressCallback({});
    result.W = grouping_.getWeightMatrix();
    result.warnings = grouping_.getWarnings();
    return result;
  }
  const GroupingParameters& parameters() const { return grouping_.getParameters(); }
  py::dict timings() const {
    const GroupingTimings& t = grouping_.getTimings();
    py::dict d;
    d["overlap"] = t.overlap_s;
    d["graph"] = t.graph_s;
    d["partition"] = t.partition_s;
    return d;
  }

 private:
  cli::PartitionArgs args_;
  InterruptFlag interrupt_{false};
  std::mutex busy_;
  ObservationGrouping<pcl::PointXYZ> grouping_;
};

// --- online grouping ---

class PyOnlineGrouping {
 public:
  explicit PyOnlineGrouping(const std::vector<std::string>& words, int exact_every) : args_(parseArgs(words)) {
    online_.setParameters(args_.method);
    online_.setExactInterval(exact_every);
    online_.setInterruptFlag(&interrupt_);
  }
  int insert(const PyObservation& observation) {
    BusyGuard busy(busy_, "the OnlineGrouping");
    return online_.insert(observation.xyz(), observation.pose);
  }
  int insertPoints(const py::array_t<float, py::array::c_style | py::array::forcecast>& points,
                   const Eigen::Matrix4d& pose) {
    BusyGuard busy(busy_, "the OnlineGrouping");
    return online_.insert(cloudOf(points), isometryOf(pose));
  }
  void updatePose(int id, const Eigen::Matrix4d& pose) {
    BusyGuard busy(busy_, "the OnlineGrouping");
    online_.updatePose(id, isometryOf(pose));
  }
  void remove(int id) {
    BusyGuard busy(busy_, "the OnlineGrouping");
    online_.remove(id);
  }
  py::dict update(bool exact) {
    BusyGuard busy(busy_, "the OnlineGrouping");
    const GroupUpdate update = runReleased([this, exact] { return exact ? online_.updateExact() : online_.update(); },
                                           interrupt_);
    py::list changes;
    for (const GroupChange& c : update.changes) changes.append(changeOf(c));
    py::dict d;
    d["changes"] = changes;
    d["exact"] = update.exact;
    d["observations_recomputed"] = update.observations_recomputed;
    d["split_nodes_reused"] = update.split_nodes_reused;
    d["split_nodes_computed"] = update.split_nodes_computed;
    d["split_nodes_ahead"] = update.split_nodes_ahead;
    return d;
  }
  std::map<int, std::vector<int>> groups() const { return online_.getGroups(); }
  int groupOf(int id) const { return online_.getGroupOf(id); }
  std::vector<int> ids() const { return online_.getIds(); }
  /// The groups after the last update, with those whose places meet through
  /// a passage joined, as the command and Grouping.compute() give them.
  PyPartition partition() const {
    Partition partition = online_.getPartition();
    joinGroupsThroughPassages(online_.getObservations(), online_.getParameters(), partition);
    return {partition, online_.getWeightMatrix(), online_.getWarnings()};
  }

 private:
  cli::PartitionArgs args_;
  InterruptFlag interrupt_{false};
  std::mutex busy_;
  OnlineGrouping<pcl::PointXYZ> online_;
};

// --- local maps and the topological map ---

struct PyLocalMap {
  LocalMap<pcl::PointXYZ> map;
};

/// The observations as PointXYZ clouds (shared when they are) at their poses.
std::vector<Observation<pcl::PointXYZ>> xyzObservations(const std::vector<PyObservation>& observations) {
  std::vector<Observation<pcl::PointXYZ>> clouds;
  clouds.reserve(observations.size());
  for (const auto& o : observations) clouds.push_back({o.xyz(), o.pose});
  return clouds;
}

/// The observations at their poses corrected by scan matching (the same
/// clouds, shared), and what correctOdometry() did, as a dict.
py::tuple correctOdometryOf(const std::vector<PyObservation>& observations, const std::string& mode_name, int threads) {
  const OdometryCorrection mode = odometryCorrectionFromString(mode_name);  // std::invalid_argument: ValueError
  std::vector<Observation<pcl::PointXYZ>> clouds = xyzObservations(observations);
  OdometryCorrectionParameters parameters;
  parameters.threads = threads;
  InterruptFlag flag{false};
  parameters.interrupt = &flag;  // Ctrl-C stops a long log's matching between steps
  const OdometryCorrectionReport r = runReleased([&] { return correctOdometry(clouds, mode, parameters); }, flag);
  std::vector<PyObservation> corrected = observations;
  for (std::size_t i = 0; i < corrected.size(); ++i) corrected[i].pose = clouds[i].pose;
  py::dict report;
  report["applied"] = r.applied;
  report["steps"] = r.steps;
  report["matched"] = r.matched;
  report["kept"] = r.kept;
  report["unaligned"] = r.unaligned;
  report["sampled"] = r.sampled;
  report["sample_matched"] = r.sample_matched;
  report["input_map_cells"] = r.input_cells;
  report["corrected_map_cells"] = r.corrected_cells;
  report["input_blocked_share"] = r.input_blocked_share;
  report["corrected_blocked_share"] = r.corrected_blocked_share;
  py::dict bias;
  bias["scale"] = r.bias.scale;
  bias["yaw_deg_per_m"] = r.bias.yaw_per_metre * 180.0 / M_PI;
  bias["turn_scale"] = r.bias.turn_scale;
  bias["steps"] = r.bias.steps;
  report["odometry_bias"] = bias;
  return py::make_tuple(corrected, report);
}

py::tuple buildLocalMaps(const std::vector<PyObservation>& observations, const PyPartition& partition,
                         const std::string& refine, double voxel, int threads, const py::object& callback) {
  const Refinement refinement = refinementFromString(refine);  // std::invalid_argument: ValueError
  if (partition.partition.group_of.size() != observations.size())
    throw py::value_error("the partition groups " + std::to_string(partition.partition.group_of.size()) +
                          " observations, not the " + std::to_string(observations.size()) + " given");
  std::vector<Observation<pcl::PointXYZ>> clouds = xyzObservations(observations);
  LocalMapBuilder<pcl::PointXYZ> builder;
  builder.setRefinement(refinement);
  builder.setVoxelLeafSize(voxel);
  builder.setNumberOfThreads(threads);
  InterruptFlag flag{false};
  builder.setInterruptFlag(&flag);
  ProgressRelay progress(callback, flag);
  builder.setProgressCallback([&progress](std::size_t done, std::size_t total) { progress("local maps", done, total); });
  std::vector<LocalMap<pcl::PointXYZ>> maps =
      runReleased([&] { return builder.build(clouds, partition.partition, partition.W); }, flag, &progress);
  std::vector<LocalMapFrame> frames;
  std::vector<Eigen::Isometry3d> poses;
  for (const auto& m : maps) frames.push_back(m.frame);
  for (const auto& o : observations) poses.push_back(o.pose);
  const TopologicalMap topology = buildTopologicalMap(std::move(frames), partition.W, poses, threads);
  py::list local_maps;
  for (auto& m : maps) local_maps.append(PyLocalMap{std::move(m)});
  py::list arcs;
  for (const TopologicalArc& a : topology.arcs) {
    py::dict d;
    d["from"] = a.from;
    d["to"] = a.to;
    d["transform"] = Eigen::Matrix4d(a.transform.matrix());
    d["translation_spread"] = a.translation_spread;
    d["rotation_spread"] = a.rotation_spread;
    d["weight"] = a.weight;
    d["overlapping_pairs"] = a.overlapping_pairs;
    d["sequence_pairs"] = a.sequence_pairs;
    d["pairs"] = a.pairs;
    arcs.append(d);
  }
  return py::make_tuple(local_maps, arcs);
}

// --- places ---

py::tuple locate(const PlaceMap& places, double x, double y, double tolerance) {
  const Location where = places.locate(Eigen::Vector2d(x, y), tolerance);
  return py::make_tuple(where.place ? py::object(py::int_(*where.place)) : py::object(py::none()), where.distance_m);
}

// --- the command ---

int runCommand(const std::vector<std::string>& words, const py::object& callback) {
  const std::vector<const char*> argv = argvOf(words);
  const cli::ParsedCommandLine parsed = cli::parseCommandLine(int(argv.size()), argv.data());
  if (!parsed.args) {
    if (!parsed.error.empty()) throw io::UsageError(parsed.error);
    return parsed.exit_code;
  }
  cli::PartitionArgs args = *parsed.args;
  InterruptFlag flag{false};
  args.interrupt = &flag;
  ProgressRelay progress(callback, flag);
  args.progress = std::ref(progress);
  return runReleased([&args] { return cli::runPartition(args); }, flag, &progress);
}

}  // namespace
}  // namespace obsgroup::python

PYBIND11_MODULE(_obsgroup, m) {
  using namespace obsgroup;
  using namespace obsgroup::python;
  m.doc() = "The C++ core of obsgroup (use the package `obsgroup`, not this module).";
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // obsgroup words its own errors

  static py::exception<io::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<io::UsageError> usage_error(m, "UsageError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const io::InputError& e) {
      input_error(e.what());
    } catch (const io::UsageError& e) {
      usage_error(e.what());
    } catch (const InvalidObservation& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const Interrupted& e) {
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    }
  });

  py::class_<PyObservation>(m, "Observation", "One observation: points in the sensor frame and the sensor's pose.")
      .def(py::init([](const py::array_t<float, py::array::c_style | py::array::forcecast>& points,
                       const Eigen::Matrix4d& pose, std::optional<double> stamp, std::string source) {
             return PyObservation{AnyCloud(CloudXYZ::ConstPtr(cloudOf(points))), isometryOf(pose), stamp,
                                  std::move(source)};
           }),
           py::arg("points"), py::arg("pose"), py::arg("stamp") = py::none(), py::arg("source") = "")
      .def_property_readonly("points", [](const PyObservation& o) { return pointsOf(o.cloud); },
                             "(n, 3) float32, read-only: a view of the cloud (2D scans have z = 0).")
      .def_property_readonly("pose", [](const PyObservation& o) { return Eigen::Matrix4d(o.pose.matrix()); },
                             "4x4 float64: the sensor's pose in the world frame.")
      .def_property_readonly("stamp", [](const PyObservation& o) { return o.stamp; },
                             "When it was sensed, seconds (logs and bags), or None.")
      .def_property_readonly("source", [](const PyObservation& o) { return o.source; },
                             "Where it came from: file and line, file, or bag message.")
      .def_property_readonly("point_type", &PyObservation::pointType, "'xyz', 'xyzi' or 'xyzrgb'.")
      .def_property_readonly("intensity", [](const PyObservation& o) -> py::object {
        const auto* c = std::get_if<1>(&o.cloud);
        if (!c) return py::none();
        py::array_t<float> out(py::ssize_t((*c)->size()));
        auto w = out.mutable_unchecked<1>();
        for (std::size_t i = 0; i < (*c)->size(); ++i) w(py::ssize_t(i)) = (**c)[i].intensity;
        return std::move(out);
      }, "(n,) float32 intensities of an xyzi cloud, else None.")
      .def_property_readonly("colors", [](const PyObservation& o) -> py::object {
        const auto* c = std::get_if<2>(&o.cloud);
        if (!c) return py::none();
        py::array_t<std::uint8_t> out({py::ssize_t((*c)->size()), py::ssize_t(3)});
        auto w = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < (*c)->size(); ++i) {
          w(py::ssize_t(i), 0) = (**c)[i].r;
          w(py::ssize_t(i), 1) = (**c)[i].g;
          w(py::ssize_t(i), 2) = (**c)[i].b;
        }
        return std::move(out);
      }, "(n, 3) uint8 RGB of an xyzrgb cloud, else None.")
      .def("__len__", &PyObservation::size);

  m.def("_read", &readInput, py::arg("words"), py::arg("progress") = py::none());
  m.def("_run_command", &runCommand, py::arg("words"), py::arg("progress") = py::none());

  py::class_<PyPartition>(m, "_Partition")
      .def_property_readonly("groups", [](const PyPartition& p) { return p.partition.groups; })
      .def_property_readonly("group_of", [](const PyPartition& p) { return intArray(p.partition.group_of); })
      .def_property_readonly("splits", [](const PyPartition& p) { return splitsOf(p.partition); })
      .def_property_readonly("warnings", [](const PyPartition& p) { return p.warnings; })
      .def("weight_arrays", [](const PyPartition& p) { return weightArrays(p.W); });

  py::class_<PyGrouping>(m, "_Grouping")
      .def(py::init<const std::vector<std::string>&>())
      .def("add", &PyGrouping::add)
      .def("add_points", &PyGrouping::addPoints)
      .def("__len__", &PyGrouping::size)
      .def("compute", &PyGrouping::compute, py::arg("progress") = py::none())
      .def("timings", &PyGrouping::timings)
      .def("parameters", [](const PyGrouping& g) {
        const GroupingParameters& p = g.parameters();
        py::dict d;
        d["model"] = toString(p.model);
        d["cell"] = p.regions.cell_size;
        d["range"] = p.regions.max_range;
        d["delta"] = p.match_distance;
        d["voxel"] = p.voxel_leaf;
        d["split"] = toString(p.split);
        d["ncut_threshold"] = p.ncut_threshold;
        d["boundary_passes"] = p.boundary_passes;
        d["mutual_neighbours"] = p.mutual_neighbours;
        d["mutual_neighbours_share"] = p.mutual_neighbours_share;
        d["open_floor_width"] = p.open_floor_width;
        d["threads"] = p.threads;
        return d;
      });

  py::class_<PyOnlineGrouping>(m, "_OnlineGrouping")
      .def(py::init<const std::vector<std::string>&, int>())
      .def("insert", &PyOnlineGrouping::insert)
      .def("insert_points", &PyOnlineGrouping::insertPoints)
      .def("update_pose", &PyOnlineGrouping::updatePose)
      .def("remove", &PyOnlineGrouping::remove)
      .def("update", &PyOnlineGrouping::update, py::arg("exact") = false)
      .def("groups", &PyOnlineGrouping::groups)
      .def("group_of", &PyOnlineGrouping::groupOf)
      .def("ids", &PyOnlineGrouping::ids)
      .def("partition", &PyOnlineGrouping::partition);

  py::class_<PyLocalMap>(m, "LocalMap", "One local map: its members' points merged in its reference frame.")
      .def_property_readonly("points", [](const PyLocalMap& l) { return xyzView<pcl::PointXYZ>(l.map.cloud); },
                             "(n, 3) float32, read-only: the merged, voxel-filtered points in the reference frame.")
      .def_property_readonly("members", [](const PyLocalMap& l) { return l.map.frame.members; },
                             "Observation indices, ascending.")
      .def_property_readonly("reference", [](const PyLocalMap& l) { return l.map.frame.reference; },
                             "The observation whose frame the map is in.")
      .def_property_readonly("pose", [](const PyLocalMap& l) { return Eigen::Matrix4d(l.map.frame.pose.matrix()); },
                             "4x4: the reference observation's pose in the world frame.")
      .def_property_readonly("member_poses", [](const PyLocalMap& l) {
        py::array_t<double> out({py::ssize_t(l.map.frame.member_poses.size()), py::ssize_t(4), py::ssize_t(4)});
        auto w = out.mutable_unchecked<3>();
        for (std::size_t k = 0; k < l.map.frame.member_poses.size(); ++k) {
          const Eigen::Matrix4d M = l.map.frame.member_poses[k].matrix();
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) w(py::ssize_t(k), r, c) = M(r, c);
        }
        return out;
      }, "(k, 4, 4): each member's (refined) pose in the reference frame.")
      .def_property_readonly("filtered", [](const PyLocalMap& l) { return l.map.filtered; },
                             "False when the map was too large for the voxel filter and kept whole.");
  m.def("_build_local_maps", &buildLocalMaps);
  m.def("_correct_odometry", &correctOdometryOf);

  py::class_<PlaceMap>(m, "_PlaceMap")
      .def("locate", &locate, py::arg("x"), py::arg("y"), py::arg("tolerance"));
  m.def("_read_place_labels", [](const std::string& folder) { return io::readPlaceLabels(folder); });
}
