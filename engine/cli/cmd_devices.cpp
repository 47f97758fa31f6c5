// `evlife devices`: lists the attached event cameras (DVS128 over USB) and,
// when there is none, what libusb sees and what to check.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>

#include "command.h"
#include "command_start.h"
#include "evlife/io/dvs128_device.h"
#include "exit_code.h"

namespace evlife::cli::devices_command {
namespace {

void print_help(std::FILE* out) {
  std::fprintf(out,
               "Usage: evlife devices\n\n"
               "Lists the attached event cameras (iniVation DVS128, USB 152a:8400), one per line,\n"
               "starting with the --source spec that selects it for `evlife run`:\n"
               "  dvs128:SERIAL   DVS128 serial SERIAL (bus B device D, firmware F)\n\n"
               "A camera that cannot be used is listed with the reason after \"--\".\n\n"
               "Exit status: 0 at least one usable camera listed, 3 none (the USB devices seen\n"
               "and what to check are printed), 1 libusb cannot start.\n\n"
               "Example:\n"
               "  evlife devices                       # dvs128:0123 DVS128 serial 0123 (...)\n"
               "  evlife run dvs128:0123 -o live.bin   # then record from that camera\n");
}

int run_devices(int argc, char** argv) {
  if (const auto done = start_command("devices", argc, argv, print_help, [&] {
        if (argc > 1) throw UsageError(std::string("unexpected argument '") + argv[1] + "'");
      })) {
    return *done;
  }
  try {
    const auto cameras = io::list_dvs128_devices();
    for (const auto& cam : cameras) {
      const std::string spec = cam.serial.empty() ? "dvs128" : "dvs128:" + cam.serial;
      std::printf("%-20s %s%s%s\n", spec.c_str(), cam.describe().c_str(),
                  cam.problem.empty() ? "" : "  -- ", cam.problem.c_str());
    }
    const bool usable = std::any_of(cameras.begin(), cameras.end(), [](const auto& cam) { return cam.problem.empty(); });
    if (usable) return kExitOk;
    const auto usb = io::list_usb_devices();
    if (cameras.empty()) {
      std::fprintf(stderr, "evlife devices: no event camera found (DVS128 = USB 152a:8400).\n");
    } else {
      std::fprintf(stderr, "evlife devices: no usable event camera: each one listed says why.\n");
    }
    std::fprintf(stderr, "USB devices seen: %zu\n", usb.size());
    for (const auto& d : usb) {
      std::fprintf(stderr, "  %04x:%04x  bus %d device %d\n", d.vendor_id, d.product_id, d.bus,
                   d.address);
    }
    std::fprintf(stderr, "%s\n", io::dvs128_troubleshooting().c_str());
    return kExitInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evlife devices: %s\n", e.what());
    return kExitFailure;
  }
}

}  // namespace

EVLIFE_REGISTER_COMMAND("devices", "list attached event cameras (DVS128 over USB)", run_devices);

}  // namespace evlife::cli::devices_command
