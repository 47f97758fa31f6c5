// The exit codes: one scheme for the commands and the engine
// (evlife/engine/exit_code.h; kExitOk ... are in namespace evlife).
#pragma once

#include "evlife/engine/exit_code.h"
