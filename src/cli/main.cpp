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

#include <cstdio>
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

}  // namespace

int main(int argc, char** argv) {
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
