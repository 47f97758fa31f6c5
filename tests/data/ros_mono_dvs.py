"""TEST-ONLY: a ROS 2 event_camera_msgs/EventPacket message of `mono` events (CDR, as the shared
test_data_mono_cd bag holds them) as a ROS 1 dvs_msgs/EventArray message (ts = time_base + dt),
for the test files of tests/data/ros1/make_bags.py and tests/data/mcap/make_mcap.py."""
import struct

DVS_TEXT = 'std_msgs/Header header\nuint32 height\nuint32 width\ndvs_msgs/Event[] events\n'
DVS_MD5 = '5e8beee5a6c107e504c2e78903c224b8'


class Cdr:
    def __init__(self, m):
        self.m, self.pos = m, 4

    def get(self, fmt):
        n = struct.calcsize('<' + fmt)
        self.pos = 4 + (self.pos - 4 + n - 1) // n * n
        v, = struct.unpack_from('<' + fmt, self.m, self.pos)
        self.pos += n
        return v

    def string(self):
        n = self.get('I')
        s = self.m[self.pos:self.pos + n - 1]
        self.pos += n
        return s


def ros1_header(seq, sec, nsec, frame):
    return struct.pack('<III', seq, sec, nsec) + struct.pack('<I', len(frame)) + frame


def mono_packet_as_dvs(cdr, seq):
    """The ROS 1 serialization of the dvs_msgs/EventArray holding the packet's events."""
    c = Cdr(cdr)
    c.get('i'), c.get('I'), c.string()
    height, width = c.get('I'), c.get('I')
    c.get('Q')
    time_base = c.get('Q')
    c.string(), c.get('B')
    n = c.get('I')
    payload = cdr[c.pos:c.pos + n]
    events = b''
    for k in range(n // 8):
        w, = struct.unpack_from('<Q', payload, 8 * k)
        tt = time_base + (w & 0xFFFFFFFF)
        events += struct.pack('<HHIIB', (w >> 32) & 0xFFFF, (w >> 48) & 0x7FFF, tt // 10**9, tt % 10**9, w >> 63)
    return ros1_header(seq, 0, 0, b'cam') + struct.pack('<III', height, width, n // 8) + events
