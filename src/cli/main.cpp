// obsgroup: group robot observations into consistent local maps and a
// metric-topological map (Blanco, Gonzalez, Fernandez-Madrigal, ICRA 2006).
//
// Exit codes: 0 done, 2 usage error, 3 input error, 130 interrupted (SIGINT
// or SIGTERM: the output folder is left as it was), 1 anything else.

#include <obsgroup/io/errors.h>
#include "command_line.h"
#include "partition_command.h"

#include <pcl/console/print.h>

#include <signal.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

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

/// Settings the C and OpenMP runtimes read once, when the program is loaded,
/// so the command sets them by starting itself again, once, with them in
/// its environment. A setting the user gave (even empty) is theirs and kept.
///
/// - GLIBC_TUNABLES=glibc.malloc.hugetlb=1, where the kernel gives
///   transparent huge pages on request: a large run writes gigabytes of
///   freshly mapped memory, and on 4 KiB pages the page faults cost about a
///   quarter of it (100,100 scans: 1.4 million faults, 12 s of system time
///   of a 36 s run; docs/performance.md). glibc backs its heap with huge
///   pages only when asked at start-up.
/// - OMP_WAIT_POLICY=passive: by default an idle OpenMP thread spins, waiting
///   for the next parallel loop. `stream` runs thousands of small loops, and
///   on a machine whose cores are busy with other work (a robot's, always)
///   the spinning threads take the cores the working ones wait for: the
///   1,001-scan stream took 26-30 s instead of 11 s beside one busy process
///   on 2 cores (docs/performance.md, "Beside other work"). On a quiet
///   machine sleeping threads cost the stream a tenth to a half (10-13 s
///   against 9 s), the batch runs nothing measurable.
void startWithRuntimeSettings(char** argv) {
#if defined(__linux__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  // Started again already: never a second time (a setuid program, say,
  // whose loader drops GLIBC_TUNABLES), and nothing left for its children.
  if (std::getenv("OBSGROUP_RESTARTED") != nullptr) {
    unsetenv("OBSGROUP_RESTARTED");
    return;
  }
  bool changed = false;
  const auto setIfUnset = [&changed](const char* name, const char* value) {
    if (std::getenv(name) != nullptr) return false;
    if (setenv(name, value, 0) != 0) return false;
    changed = true;
    return true;
  };
  bool tunables_set = false;
#if defined(__GLIBC__)
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  // "always": huge pages already; "never": no use.
  if (std::getline(mode, modes) && modes.find("[madvise]") != std::string::npos)
    tunables_set = setIfUnset("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1");
#endif
  const bool wait_set = setIfUnset("OMP_WAIT_POLICY", "passive");
  if (!changed) return;
  if (setenv("OBSGROUP_RESTARTED", "1", 1) == 0) execv("/proc/self/exe", argv);
  // Not started again: carry on as it is.
  unsetenv("OBSGROUP_RESTARTED");
  if (tunables_set) unsetenv("GLIBC_TUNABLES");
  if (wait_set) unsetenv("OMP_WAIT_POLICY");
#else
  (void)argv;
#endif
}

/// The stages of a large run free and allocate hundreds of megabytes in
/// turn. By default glibc grows its heap by exactly what each allocation
/// lacks and gives the top back as soon as it is free, so the next stage
/// faults the same pages in again (100,100 scans: about 250,000 page faults,
/// 4-5 s of system time). Growing it 64 MiB at a time halves the faults
/// (docs/performance.md); the run's peak is unchanged, since pages are only
/// resident once written and the stages still hand their memory back
/// (returnFreedMemory). A user's own glibc.malloc.top_pad is kept.
void padHeapGrowth() {
#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, "top_pad") != nullptr) return;
  mallopt(M_TOP_PAD, 64 << 20);
#endif
}

}  // namespace

int main(int argc, char** argv) {
  startWithRuntimeSettings(argv);
  padHeapGrowth();
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);  // obsgroup words its own errors

  const auto usage = [](const std::string& message) {
    std::fprintf(stderr, "obsgroup: error: %s\n", message.c_str());
    return 2;
  };
  const obsgroup::cli::ParsedCommandLine parsed = obsgroup::cli::parseCommandLine(argc, argv);
  if (!parsed.args) {
    if (!parsed.error.empty()) {
      usage(parsed.error);
      if (!parsed.help_hint.empty()) std::fprintf(stderr, "%s\n", parsed.help_hint.c_str());
    }
    return parsed.exit_code;
  }
  obsgroup::cli::PartitionArgs args = *parsed.args;
  args.interrupt = &interrupt_requested;
  catchInterrupts();
  try {
    return obsgroup::cli::runPartition(args);
  } catch (const obsgroup::Interrupted&) {
    std::fprintf(stderr, "\nobsgroup: interrupted; %s was left as it was\n", args.output.c_str());
    return 130;
  } catch (const obsgroup::io::UsageError& e) {
    return usage(e.what());
  } catch (const obsgroup::io::InputError& e) {
    std::fprintf(stderr, "obsgroup: error: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "obsgroup: error: %s\n", e.what());
    return 1;
  }
}
