// A program that only reads recordings links evlife::io_formats (and algo):
// no libusb, no writers, no simulator. `evlife_read_events FILE` prints the
// format, sensor, event count and time range; with no argument it lists the
// formats it reads. ctest io_formats_links_no_libusb checks its libraries.
#include <cstdio>
#include <exception>
#include <vector>

#include "evlife/io/event_reader.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    for (const auto& f : evlife::io::known_event_formats())
      std::printf("%.*s\n", static_cast<int>(f.name.size()), f.name.data());
    return 0;
  }
  try {
    const auto reader = evlife::io::open_event_reader(argv[1]);
    std::vector<evlife::Event> buf(1 << 16);
    unsigned long long n = 0;
    long long first = 0, last = 0;
    while (const std::size_t got = reader->read(buf)) {
      if (n == 0) first = buf[0].t_us;
      last = buf[got - 1].t_us;
      n += got;
    }
    const auto s = reader->sensor_size();
    std::printf("%s: %.*s, sensor %dx%d, %llu events, t %lld..%lld us\n", argv[1],
                static_cast<int>(reader->format_name().size()), reader->format_name().data(),
                s ? s->width : 0, s ? s->height : 0, n, first, last);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
