// sc_soc_sim: the Verilator harness of the SoC in the loop (hdl-interface/soc/sc_soc.v). It is
// the board around the core: it serves the core's Wishbone buses as the memory map of QEMU's
// `virt` machine, so that the firmware ELF QEMU runs runs here unchanged, and it is started
// and spoken to as the host's QEMU link starts and speaks to QEMU:
//
//   sc-soc-sim --elf ELF --uart SOCKET [--load FILE@ADDR]... [--frames FILE]
//              [--ram-mib N] [--max-cycles N] [--watchdog-cycles N]
//              [--pixel-clock-divider N] [--line-blank N]
//
// - RAM at 0x8000_0000 (--ram-mib, 128 as QEMU's default -m): the ELF's PT_LOAD segments and
//   every --load file are copied in before reset (QEMU's -kernel and -device loader).
// - 16550 UART at 0x1000_0000 (byte registers): THR writes go to the socket, RBR reads take
//   the bytes the host sent, LSR says DR when one waits and THRE | TEMT always (the link has
//   no baud rate). The socket is a Unix socket the harness listens on and waits for one
//   client at, as QEMU's `-chardev socket,server=on,wait=on`.
// - `sifive_test` finisher at 0x0010_0000: 0x5555 ends the run with exit status 0, 0x3333
//   with the status in bits 31..16, as QEMU does.
// - The fabrics (0x4000_0000, sc_soc.v) are in the Verilog; any other address answers with a
//   bus error (the core takes an access fault).
// - The cameras (--frames, the frame-grabber file whose layout is the firmware's
//   softcore/frame_input.rs): camera c sends the file's images of camera c in order. A
//   camera is triggered, as a global-shutter sensor in snapshot mode is: it starts an image
//   on the first pixel clock its fabric's PIXEL_IN is ready (the fabric armed, waiting for
//   SOF), so its frame blanking is the time until the driver arms the next frame; then it
//   sends one pixel per pixel clock, each line followed by --line-blank pixel clocks, and
//   never waits: a pixel the fabric does not take ends the run with status 125 and a
//   message. The default line blanking, 16 pixel clocks, is shorter than a real sensor's
//   (VGA timing has 160, an MT9V034 at least 61): the fabric's work at a line's end must fit
//   in it, so the shortest is the hardest case. A pixel clock is one clock in
//   --pixel-clock-divider (default 32: the stream engine's pace, docs/STREAM_ENGINE.md; at 1
//   the engine falls behind and the frame stops with STREAM_FAULT.OVERRUN).
// - The link: the UART's bytes and both LINK_OUT ports share the socket at link-frame
//   boundaries: a source that has begun a frame keeps the socket until its 0x00 delimiter,
//   the others' bytes wait (a link arbiter; LINK_OUT is always ready).
// - The report port at 0x4002_0000 (firmware softcore/soc.rs): six write-only words FRAME,
//   CAMERA, POINT_OVERFLOWS, SOBEL_OVERFLOWS, BUSY_WAIT_CYCLES, CYCLES; a write of CYCLES
//   prints the record as `sc_soc_sim: image frame F camera C softcore_cycles N
//   busy_wait_cycles N point_overflows P sobel_overflows S`.
// - --max-cycles (default: none) ends a run that did not finish with exit status 124 and a
//   message naming the limit; the host reports the status and the message.
// - The watchdog: a run in which nothing moves for --watchdog-cycles clocks (default
//   twenty line times of a 640-pixel line, at least 400,000: `default_watchdog`; 0 turns it
//   off) ends with exit status 124 and a message saying what stood still and where the core
//   last fetched. Moving is a camera pixel taken or a byte on the
//   link either way; polling registers is not (a firmware stuck waiting for a camera that
//   never sends polls STATUS forever). A healthy run's longest stillness is printed at exit
//   (`longest_still`), well below the default (hdl-interface/soc/README.md).
//
// Both buses get zero-wait-state answers: the harness acknowledges every clock on which a
// bus holds STB, one transfer per acknowledged clock, so a register read has exactly one
// effect. On exit it prints to stderr, per camera image, `sc_soc_sim: timing camera C image I
// first_pixel N last_pixel N first_byte N last_byte N` (clocks: the image's first and last
// pixel taken, the first and last byte its fabric's LINK_OUT sent for it, from its FrameStart,
// which leaves at FRAME_ARM, to its last delimiter), then one line `sc_soc_sim: cycles N millis N fabric_reads N fabric_writes N
// longest_still N pixel_clock_divider N` (millis: the simulation's wall time).

#include <elf.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "Vsc_soc.h"
#include "verilated.h"

namespace {

constexpr uint32_t RAM_BASE = 0x80000000u;
constexpr uint32_t UART_BASE = 0x10000000u;
constexpr uint32_t FINISHER = 0x00100000u;
constexpr uint32_t REPORT_PORT = 0x40020000u;
// FRAME, CAMERA, POINT_OVERFLOWS, SOBEL_OVERFLOWS, BUSY_WAIT_CYCLES, CYCLES
constexpr uint32_t REPORT_WORDS = 6;

/// A board that cannot run (bad arguments, a file it cannot read) ends with status 64
/// (EX_USAGE), which no firmware exit code is: the host must not read it as the firmware's.
[[noreturn]] void die(const std::string &what) {
    std::fprintf(stderr, "sc_soc_sim: %s\n", what.c_str());
    std::exit(64);
}

std::vector<uint8_t> read_file(const std::string &path) {
    FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) die("cannot open " + path + ": " + std::strerror(errno));
    std::vector<uint8_t> bytes;
    uint8_t buf[65536];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) bytes.insert(bytes.end(), buf, buf + n);
    std::fclose(f);
    return bytes;
}

struct Ram {
    std::vector<uint8_t> bytes;
    bool holds(uint32_t addr, uint32_t len) const {
        return addr >= RAM_BASE && uint64_t(addr - RAM_BASE) + len <= bytes.size();
    }
    void load(uint32_t addr, const uint8_t *data, size_t len, const std::string &what) {
        if (!holds(addr, uint32_t(len))) die(what + " does not fit the RAM");
        std::memcpy(&bytes[addr - RAM_BASE], data, len);
    }
};

void load_elf(Ram &ram, const std::string &path) {
    std::vector<uint8_t> f = read_file(path);
    if (f.size() < sizeof(Elf32_Ehdr)) die(path + ": not an ELF file");
    Elf32_Ehdr eh;
    std::memcpy(&eh, f.data(), sizeof eh);
    if (std::memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS32 ||
        eh.e_machine != EM_RISCV)
        die(path + ": not a 32-bit RISC-V ELF file");
    for (unsigned i = 0; i < eh.e_phnum; i++) {
        size_t at = size_t(eh.e_phoff) + size_t(i) * eh.e_phentsize;
        if (at + sizeof(Elf32_Phdr) > f.size()) die(path + ": truncated program headers");
        Elf32_Phdr ph;
        std::memcpy(&ph, &f[at], sizeof ph);
        if (ph.p_type != PT_LOAD || ph.p_memsz == 0) continue;
        if (size_t(ph.p_offset) + ph.p_filesz > f.size()) die(path + ": truncated segment");
        if (!ram.holds(ph.p_paddr, ph.p_memsz)) die(path + ": a segment lies outside the RAM");
        std::memset(&ram.bytes[ph.p_paddr - RAM_BASE], 0, ph.p_memsz);
        ram.load(ph.p_paddr, &f[ph.p_offset], ph.p_filesz, path);
    }
}

/// The UART's socket: one client, accepted before the run starts.
struct Uart {
    int fd = -1;
    std::deque<uint8_t> rx;
    bool closed = false;

    void listen_and_accept(const std::string &path) {
        int s = socket(AF_UNIX, SOCK_STREAM, 0);
        if (s < 0) die(std::string("socket: ") + std::strerror(errno));
        sockaddr_un addr{};
        addr.sun_family = AF_UNIX;
        if (path.size() >= sizeof addr.sun_path) die("socket path too long: " + path);
        std::strcpy(addr.sun_path, path.c_str());
        unlink(path.c_str());
        if (bind(s, reinterpret_cast<sockaddr *>(&addr), sizeof addr) != 0)
            die("bind " + path + ": " + std::strerror(errno));
        if (listen(s, 1) != 0) die(std::string("listen: ") + std::strerror(errno));
        fd = accept(s, nullptr, nullptr);
        if (fd < 0) die(std::string("accept: ") + std::strerror(errno));
        close(s);
    }

    /// Takes what the host has sent, without waiting.
    void poll_rx() {
        if (closed) return;
        pollfd p{fd, POLLIN, 0};
        if (poll(&p, 1, 0) <= 0) return;
        uint8_t buf[4096];
        ssize_t n = read(fd, buf, sizeof buf);
        if (n > 0)
            rx.insert(rx.end(), buf, buf + n);
        else if (n == 0)
            closed = true;
    }

    void send(uint8_t byte) {
        if (closed) return;
        // The host reads as it goes; a full socket buffer holds the simulation, as a UART
        // whose FIFO is full holds its writer.
        while (write(fd, &byte, 1) != 1) {
            if (errno != EINTR && errno != EAGAIN) {
                closed = true;
                return;
            }
        }
    }
};

/// The link arbiter: whole link frames from each source, in the order they begin.
struct Link {
    std::deque<uint8_t> queue[3];   // UART, LINK_OUT 0, LINK_OUT 1
    int owner = -1;
    Uart *uart = nullptr;

    void push(int source, uint8_t byte) {
        queue[source].push_back(byte);
        pump();
    }

    void pump() {
        for (;;) {
            if (owner < 0) {
                for (int s = 0; s < 3 && owner < 0; s++)
                    if (!queue[s].empty()) owner = s;
                if (owner < 0) return;
            }
            std::deque<uint8_t> &q = queue[owner];
            while (!q.empty()) {
                uint8_t b = q.front();
                q.pop_front();
                uart->send(b);
                if (b == 0) {
                    owner = -1;
                    break;
                }
            }
            if (owner >= 0) return;   // the frame goes on later
        }
    }
};

/// When an image went in and its packets came out, in clocks.
struct Timing {
    uint64_t first_pixel = 0, last_pixel = 0, first_byte = 0, last_byte = 0;
    bool any_byte = false;
};

/// The images of one camera from a frame-grabber file.
struct Camera {
    std::vector<const uint8_t *> images;
    size_t next = 0;     // image to send next
    size_t at = 0;       // pixel of the current image; 0 and !sending: waiting for the trigger
    bool sending = false;
    uint64_t blank = 0;  // pixel clocks of line blanking left
    std::vector<Timing> timing;   // one per image begun
    // LINK_OUT's link frames: where the latest began, the byte before it, the latest byte.
    bool in_frame = false;
    uint64_t frame_begin = 0, byte_before_frame = 0, latest_byte = 0;
    bool any_byte = false, byte_before = false;

    /// A byte left this camera's LINK_OUT; it belongs to the image begun last.
    void byte_out(uint64_t cycle, uint8_t byte) {
        if (!in_frame) {
            byte_before = any_byte;
            byte_before_frame = latest_byte;
            frame_begin = cycle;
            in_frame = true;
        }
        if (byte == 0) in_frame = false;
        any_byte = true;
        latest_byte = cycle;
        if (timing.empty()) return;
        Timing &t = timing.back();
        if (!t.any_byte) t.first_byte = cycle;
        t.any_byte = true;
        t.last_byte = cycle;
    }

    /// The image's first pixel went in, on the first pixel clock after FRAME_ARM. Every byte
    /// of the image before left before the arm (the driver arms once BUSY fell after that
    /// image's last delimiter, hundreds of clocks of its own work before), and the new
    /// image's FrameStart begins at the arm: so a link frame begun within the last pixel
    /// clock is the new image's, and the bytes before it the previous image's; otherwise
    /// the FrameStart is still to come.
    void image_begins(uint64_t cycle, uint64_t divider) {
        bool started = any_byte && cycle - frame_begin <= divider;
        if (started && !timing.empty() && byte_before) timing.back().last_byte = byte_before_frame;
        timing.emplace_back();
        Timing &t = timing.back();
        t.first_pixel = cycle;
        if (started) {
            t.any_byte = true;
            t.first_byte = frame_begin;
            t.last_byte = latest_byte;
        }
    }
};

struct Args {
    std::string elf, uart, frames;
    uint64_t divider = 32, line_blank = 16;
    std::vector<std::pair<std::string, uint32_t>> loads;
    uint64_t ram_mib = 128;
    uint64_t max_cycles = 0;
    // --watchdog-cycles; unset: `default_watchdog`.
    std::optional<uint64_t> watchdog;
};

/// The widest line the board's fabrics take (sc_soc.v's sc_fabric instances).
constexpr uint64_t MAX_LINE = 640;

/// The watchdog's limit when --watchdog-cycles is not given: twenty line times of the widest
/// line (its pixels and the blanking, in pixel clocks of `divider` clocks), and never below
/// 400,000 clocks. A healthy run's longest stillness is at most about one line time: in the
/// flush after an image's last line no pixel goes in, and the stream engine has nothing to
/// send until the line time ends (640x480: 20,300 clocks at one pixel clock in 32, 40,125 at
/// one in 64; `stereocal hil --soc --width 640 --height 480 --json`,
/// sim_longest_still_clocks). The floor keeps room for the stillness counted in clocks, not
/// pixel clocks (the engine's end-of-frame passes), the larger part at a fast pixel clock.
uint64_t default_watchdog(uint64_t divider, uint64_t line_blank) {
    return std::max<uint64_t>(400000, 20 * (MAX_LINE + line_blank) * divider);
}

Args parse(int argc, char **argv) {
    Args a;
    for (int i = 1; i < argc; i++) {
        std::string k = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) die(k + " needs a value");
            return argv[++i];
        };
        if (k == "--elf") {
            a.elf = value();
        } else if (k == "--uart") {
            a.uart = value();
        } else if (k == "--load") {
            std::string v = value();
            size_t at = v.rfind('@');
            if (at == std::string::npos) die("--load wants FILE@ADDR, got " + v);
            a.loads.emplace_back(v.substr(0, at),
                                 uint32_t(std::strtoul(v.c_str() + at + 1, nullptr, 0)));
        } else if (k == "--frames") {
            a.frames = value();
        } else if (k == "--pixel-clock-divider") {
            a.divider = std::strtoull(value().c_str(), nullptr, 0);
            // The firmware's waits for a camera allow 4096 core clocks per pixel clock
            // (softcore/wired.rs, MAX_CORE_CLOCKS_PER_PIXEL).
            if (a.divider == 0 || a.divider > 4096)
                die("--pixel-clock-divider must be 1 to 4096");
        } else if (k == "--line-blank") {
            a.line_blank = std::strtoull(value().c_str(), nullptr, 0);
        } else if (k == "--ram-mib") {
            a.ram_mib = std::strtoull(value().c_str(), nullptr, 0);
        } else if (k == "--max-cycles") {
            a.max_cycles = std::strtoull(value().c_str(), nullptr, 0);
        } else if (k == "--watchdog-cycles") {
            a.watchdog = std::strtoull(value().c_str(), nullptr, 0);
        } else {
            die("unknown argument " + k);
        }
    }
    if (a.elf.empty() || a.uart.empty()) die("usage: sc_soc_sim --elf ELF --uart SOCKET ...");
    if (!a.watchdog.has_value()) a.watchdog = default_watchdog(a.divider, a.line_blank);
    return a;
}

}  // namespace

extern "C" int sc_soc_sim_main(int argc, char **argv) {
    Args args = parse(argc, argv);
    Ram ram;
    ram.bytes.assign(size_t(args.ram_mib) << 20, 0);
    load_elf(ram, args.elf);
    for (auto &[path, addr] : args.loads) {
        std::vector<uint8_t> data = read_file(path);
        ram.load(addr, data.data(), data.size(), path);
    }
    // The cameras' images: the frame-grabber file's header (magic, version, cameras, width,
    // height, flags, frame_count), then per frame one record per camera (timestamp, pixels).
    std::vector<uint8_t> frames;
    Camera cams[2];
    uint32_t width = 0, height = 0;
    if (!args.frames.empty()) {
        frames = read_file(args.frames);
        if (frames.size() < 16 || std::memcmp(frames.data(), "SCFI", 4) != 0)
            die(args.frames + ": not a frame-grabber file");
        uint32_t cameras = frames[5];
        width = frames[6] | (frames[7] << 8);
        height = frames[8] | (frames[9] << 8);
        uint32_t count;
        std::memcpy(&count, &frames[12], 4);
        size_t record = 8 + size_t(width) * height, off = 16;
        if (cameras < 1 || cameras > 2 || width == 0 || height == 0 ||
            off + record * cameras * count > frames.size())
            die(args.frames + ": truncated, an empty image or not 1 or 2 cameras");
        for (uint32_t f = 0; f < count; f++)
            for (uint32_t c = 0; c < cameras; c++, off += record)
                cams[c].images.push_back(&frames[off + 8]);
    }

    Uart uart;
    uart.listen_and_accept(args.uart);
    Link link;
    link.uart = &uart;

    VerilatedContext ctx;
    Vsc_soc top{&ctx};
    auto t0 = std::chrono::steady_clock::now();
    uint64_t cycle = 0;
    int exit_status = -1;
    uint64_t last_move = 0, longest_still = 0, last_fetch = 0;
    uint32_t report[REPORT_WORDS] = {};

    auto edge = [&]() {
        top.clk = 1;
        top.eval();
        top.clk = 0;
        top.eval();
        cycle++;
    };
    top.clk = 0;
    top.reset = 1;
    top.ibus_ack = top.ibus_err = top.dbus_ack = top.dbus_err = 0;
    top.eval();
    for (int i = 0; i < 16; i++) edge();
    top.reset = 0;
    top.eval();

    while (exit_status < 0) {
        uint64_t still = cycle - last_move;
        if (still > longest_still) longest_still = still;
        if (*args.watchdog && still >= *args.watchdog) {
            std::fprintf(stderr, "sc_soc_sim: watchdog: nothing moved for %llu clocks (no "
                         "camera pixel taken, no byte on the link either way) since clock "
                         "%llu; the core last fetched at 0x%08x: the firmware hangs\n",
                         static_cast<unsigned long long>(still),
                         static_cast<unsigned long long>(last_move), unsigned(last_fetch));
            exit_status = 124;
            break;
        }
        if (args.max_cycles && cycle >= args.max_cycles) {
            std::fprintf(stderr, "sc_soc_sim: the firmware did not finish within %llu cycles "
                         "(data bus %s at 0x%08x, instruction bus %s at 0x%08x)\n",
                         static_cast<unsigned long long>(args.max_cycles),
                         top.dbus_cyc ? (top.dbus_we ? "writing" : "reading") : "idle",
                         unsigned(top.dbus_adr) << 2, top.ibus_cyc ? "fetching" : "idle",
                         unsigned(top.ibus_adr) << 2);
            exit_status = 124;
            break;
        }
        // Instruction bus: RAM only.
        top.ibus_ack = 0;
        top.ibus_err = 0;
        if (top.ibus_cyc && top.ibus_stb) {
            uint32_t addr = uint32_t(top.ibus_adr) << 2;
            last_fetch = addr;
            if (ram.holds(addr, 4)) {
                uint32_t w;
                std::memcpy(&w, &ram.bytes[addr - RAM_BASE], 4);
                top.ibus_dat_r = w;
                top.ibus_ack = 1;
            } else {
                top.ibus_err = 1;
            }
        }
        // Data bus.
        top.dbus_ack = 0;
        top.dbus_err = 0;
        if (top.dbus_cyc && top.dbus_stb) {
            uint32_t addr = uint32_t(top.dbus_adr) << 2;
            uint32_t sel = top.dbus_sel, wdata = top.dbus_dat_w;
            if (ram.holds(addr, 4)) {
                uint8_t *p = &ram.bytes[addr - RAM_BASE];
                if (top.dbus_we) {
                    for (int b = 0; b < 4; b++)
                        if (sel & (1u << b)) p[b] = uint8_t(wdata >> (8 * b));
                } else {
                    uint32_t w;
                    std::memcpy(&w, p, 4);
                    top.dbus_dat_r = w;
                }
                top.dbus_ack = 1;
            } else if (addr >= UART_BASE && addr < UART_BASE + 8) {
                uint32_t rdata = 0;
                for (int b = 0; b < 4; b++) {
                    if (!(sel & (1u << b))) continue;
                    uint32_t reg = addr - UART_BASE + b;
                    uint8_t v = 0;
                    if (top.dbus_we) {
                        if (reg == 0) {
                            link.push(0, uint8_t(wdata >> (8 * b)));
                            last_move = cycle;
                        }
                    } else if (reg == 0) {
                        if (uart.rx.empty()) uart.poll_rx();
                        if (!uart.rx.empty()) {
                            v = uart.rx.front();
                            uart.rx.pop_front();
                            last_move = cycle;
                        }
                    } else if (reg == 5) {
                        if (uart.rx.empty()) uart.poll_rx();
                        v = uint8_t(0x60 | (uart.rx.empty() ? 0 : 1));
                    }
                    rdata |= uint32_t(v) << (8 * b);
                }
                top.dbus_dat_r = rdata;
                top.dbus_ack = 1;
            } else if (addr == FINISHER) {
                if (top.dbus_we) {
                    uint32_t code = wdata & 0xffff;
                    if (code == 0x5555)
                        exit_status = 0;
                    else if (code == 0x3333)
                        exit_status = int(wdata >> 16);
                }
                top.dbus_dat_r = 0;
                top.dbus_ack = 1;
            } else if (addr >= REPORT_PORT && addr < REPORT_PORT + 4 * REPORT_WORDS) {
                uint32_t word = (addr - REPORT_PORT) / 4;
                if (top.dbus_we) report[word] = wdata;
                if (top.dbus_we && word == REPORT_WORDS - 1)
                    std::fprintf(stderr, "sc_soc_sim: image frame %u camera %u softcore_cycles %u "
                                 "busy_wait_cycles %u point_overflows %u sobel_overflows %u\n",
                                 report[0], report[1], report[5], report[4], report[2],
                                 report[3]);
                top.dbus_dat_r = 0;
                top.dbus_ack = 1;
            } else {
                std::fprintf(stderr, "sc_soc_sim: bus error at 0x%08x (%s)\n", addr,
                             top.dbus_we ? "write" : "read");
                top.dbus_err = 1;
            }
        }
        // The cameras, on pixel clocks: each offers its pixel (a waiting camera the first
        // pixel of its next image) and it is taken when PIXEL_IN is ready on this clock.
        bool ce = cycle % args.divider == 0;
        top.pix_ce = ce;
        top.link_ready = 3;
        uint32_t cam_data = 0, valid = 0, sof = 0, eol = 0;
        for (int c = 0; c < 2 && ce; c++) {
            Camera &cam = cams[c];
            if (cam.sending && cam.blank > 0) {
                cam.blank--;
                continue;
            }
            if (!cam.sending && cam.next >= cam.images.size()) continue;
            size_t at = cam.sending ? cam.at : 0;
            cam_data |= uint32_t(cam.images[cam.next][at]) << (8 * c);
            valid |= 1u << c;
            if (at == 0) sof |= 1u << c;
            if ((at + 1) % width == 0) eol |= 1u << c;
        }
        top.cam_data = cam_data;
        top.cam_valid = valid;
        top.cam_sof = sof;
        top.cam_eol = eol;
        top.clk = 0;
        top.eval();
        for (int c = 0; c < 2; c++) {
            if ((top.link_valid >> c) & 1) {
                link.push(1 + c, uint8_t(top.link_data >> (8 * c)));
                cams[c].byte_out(cycle, uint8_t(top.link_data >> (8 * c)));
                last_move = cycle;
            }
            if (!((valid >> c) & 1)) continue;
            Camera &cam = cams[c];
            bool taken = (top.cam_ready >> c) & 1;
            if (!taken) {
                if (!cam.sending) continue;   // not triggered yet: the fabric is not armed
                std::fprintf(stderr,
                             "sc_soc_sim: camera %d: pixel %zu of image %zu not taken (the "
                             "fabric was not ready)\n",
                             c, cam.at, cam.next);
                exit_status = 125;
                continue;
            }
            if (!cam.sending) {
                cam.sending = true;
                cam.at = 0;
                cam.image_begins(cycle, args.divider);
            }
            cam.timing.back().last_pixel = cycle;
            last_move = cycle;
            cam.at++;
            if (cam.at % width == 0) cam.blank = args.line_blank;
            if (cam.at == size_t(width) * height) {
                cam.sending = false;
                cam.blank = 0;
                cam.next++;
            }
        }
        top.clk = 1;
        top.eval();
        cycle++;
    }

    auto millis = std::chrono::duration_cast<std::chrono::milliseconds>(
                      std::chrono::steady_clock::now() - t0)
                      .count();
    for (int c = 0; c < 2; c++)
        for (size_t i = 0; i < cams[c].timing.size(); i++) {
            const Timing &t = cams[c].timing[i];
            std::fprintf(stderr, "sc_soc_sim: timing camera %d image %zu first_pixel %llu "
                         "last_pixel %llu first_byte %llu last_byte %llu\n", c, i,
                         static_cast<unsigned long long>(t.first_pixel),
                         static_cast<unsigned long long>(t.last_pixel),
                         static_cast<unsigned long long>(t.first_byte),
                         static_cast<unsigned long long>(t.last_byte));
        }
    std::fprintf(stderr, "sc_soc_sim: cycles %llu millis %lld fabric_reads %u fabric_writes %u "
                 "longest_still %llu pixel_clock_divider %llu\n",
                 static_cast<unsigned long long>(cycle), static_cast<long long>(millis),
                 unsigned(top.fabric_reads), unsigned(top.fabric_writes),
                 static_cast<unsigned long long>(longest_still),
                 static_cast<unsigned long long>(args.divider));
    top.final();
    if (uart.fd >= 0) close(uart.fd);
    return exit_status;
}
