// Exit codes shared by every evlife subcommand (documented in --help and the README).
#pragma once

namespace evlife::cli {

enum ExitCode : int {
  kExitOk = 0,
  kExitFailure = 1,       ///< anything else (a bug, out of memory)
  kExitUsage = 2,         ///< bad command line or configuration
  kExitInput = 3,         ///< input missing, unknown format, corrupt or invalid data
  kExitOutput = 4,        ///< output cannot be created or written
  kExitRealtime = 5,      ///< `run`: a real-time setting (--cpus, --rt-priority, --lock-memory) refused
  kExitInterrupted = 130  ///< SIGINT/SIGTERM: output flushed up to the stop
};

}  // namespace evlife::cli
