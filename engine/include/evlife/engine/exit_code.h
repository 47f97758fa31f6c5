// The exit codes of evlife: every `evlife` command (documented in --help and
// the README) and RunResult::exit_code() of the engine use this one scheme.
#pragma once

namespace evlife {

enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,       ///< anything else (a bug, out of memory)
  kExitUsage = 2,         ///< bad command line or configuration
  kExitInput = 3,         ///< input missing, unknown format, corrupt or invalid data
  kExitOutput = 4,        ///< output cannot be created or written
  kExitRealtime = 5,      ///< `run`: a real-time setting (--cpus, --rt-priority, --lock-memory) refused
  kExitInterrupted = 130  ///< SIGINT/SIGTERM: output flushed up to the stop
};

}  // namespace evlife
