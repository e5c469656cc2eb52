// sc_soc_sim: the Verilator harness of the SoC in the loop (hdl-interface/soc/sc_soc.v). It is
// the board around the core: it serves the core's Wishbone buses as the memory map of QEMU's
// `virt` machine, so that the firmware ELF QEMU runs runs here unchanged, and it is started
// and spoken to as the host's QEMU link starts and speaks to QEMU:
//
//   sc_soc_sim --elf ELF --uart SOCKET [--load FILE@ADDR]... [--ram-mib N] [--max-cycles N]
//
// - RAM at 0x8000_0000 (--ram-mib, 128 as QEMU's default -m): the ELF's PT_LOAD segments and
//   every --load file are copied in before reset (QEMU's -kernel and -device loader).
// - 16550 UART at 0x1000_0000 (byte registers): THR writes go to the socket, RBR reads take
//   the bytes the host sent, LSR says DR when one waits and THRE | TEMT always (the link has
//   no baud rate). The socket is a Unix socket the harness listens on and waits for one
//   client at, as QEMU's `-chardev socket,server=on,wait=on`.
// - `sifive_test` finisher at 0x0010_0000: 0x5555 ends the run with exit status 0, 0x3333
//   with the status in bits 31..16, as QEMU does.
// - Any other address answers with a bus error (the core takes an access fault).
// - --max-cycles (default: none) ends a run that did not finish with exit status 124 and a
//   message naming the limit; the host side reports it as a timeout.
//
// Both buses get zero-wait-state answers: the harness acknowledges every clock on which a
// bus holds STB, one transfer per acknowledged clock, so a register read has exactly one
// effect. On exit it prints to stderr one line `sc_soc_sim: cycles N seconds S`.

#include <elf.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "Vsc_soc.h"
#include "verilated.h"

namespace {

constexpr uint32_t RAM_BASE = 0x80000000u;
constexpr uint32_t UART_BASE = 0x10000000u;
constexpr uint32_t FINISHER = 0x00100000u;

[[noreturn]] void die(const std::string &what) {
    std::fprintf(stderr, "sc_soc_sim: %s\n", what.c_str());
    std::exit(2);
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

struct Args {
    std::string elf, uart;
    std::vector<std::pair<std::string, uint32_t>> loads;
    uint64_t ram_mib = 128;
    uint64_t max_cycles = 0;
};

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
        } else if (k == "--ram-mib") {
            a.ram_mib = std::strtoull(value().c_str(), nullptr, 0);
        } else if (k == "--max-cycles") {
            a.max_cycles = std::strtoull(value().c_str(), nullptr, 0);
        } else {
            die("unknown argument " + k);
        }
    }
    if (a.elf.empty() || a.uart.empty()) die("usage: sc_soc_sim --elf ELF --uart SOCKET ...");
    return a;
}

}  // namespace

int main(int argc, char **argv) {
    Args args = parse(argc, argv);
    Ram ram;
    ram.bytes.assign(size_t(args.ram_mib) << 20, 0);
    load_elf(ram, args.elf);
    for (auto &[path, addr] : args.loads) {
        std::vector<uint8_t> data = read_file(path);
        ram.load(addr, data.data(), data.size(), path);
    }
    Uart uart;
    uart.listen_and_accept(args.uart);

    VerilatedContext ctx;
    Vsc_soc top{&ctx};
    auto t0 = std::chrono::steady_clock::now();
    uint64_t cycle = 0;
    int exit_status = -1;

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
        if (args.max_cycles && cycle >= args.max_cycles) {
            std::fprintf(stderr, "sc_soc_sim: the firmware did not finish within %llu cycles\n",
                         static_cast<unsigned long long>(args.max_cycles));
            exit_status = 124;
            break;
        }
        // Instruction bus: RAM only.
        top.ibus_ack = 0;
        top.ibus_err = 0;
        if (top.ibus_cyc && top.ibus_stb) {
            uint32_t addr = uint32_t(top.ibus_adr) << 2;
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
                        if (reg == 0) uart.send(uint8_t(wdata >> (8 * b)));
                    } else if (reg == 0) {
                        if (uart.rx.empty()) uart.poll_rx();
                        if (!uart.rx.empty()) {
                            v = uart.rx.front();
                            uart.rx.pop_front();
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
            } else {
                std::fprintf(stderr, "sc_soc_sim: bus error at 0x%08x (%s)\n", addr,
                             top.dbus_we ? "write" : "read");
                top.dbus_err = 1;
            }
        }
        top.eval();
        edge();
    }

    double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::fprintf(stderr, "sc_soc_sim: cycles %llu seconds %.3f\n",
                 static_cast<unsigned long long>(cycle), seconds);
    top.final();
    if (uart.fd >= 0) close(uart.fd);
    return exit_status;
}
