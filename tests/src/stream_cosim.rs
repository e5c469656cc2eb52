//! The stream engine's co-simulation: the same frames, configurations and register writes
//! into the device model (clocked, its stream engine on a link that collects the bytes) and
//! into the Verilated `sc_fabric` with its RTL engine (`sc_stream.v`), comparing every byte on
//! LINK_OUT and the engine's registers after each frame.
//!
//! The RTL runs the datapath on one clock in `ratio` (PIXEL_IN's pixel-clock enable, a camera
//! at one pixel per pixel clock with line blanking) while the engine and its framer run on
//! every clock, with LINK_OUT's ready dropped at random. The model's engine takes its FIFOs
//! at each line time in zero time; the RTL's equals it byte for byte while it keeps up, and
//! says so when it does not (STREAM_FAULT.OVERRUN): then what it sent is a prefix of the
//! model's bytes, ending at a link frame.

use stereocal_firmware::fabric::device::{Access, Beat};
use stereocal_firmware::fabric::{FabricDevice, RegisterFrontEnd};
use stereocal_firmware::framing::ByteSink;
use stereocal_hdl::regs::{
    control, frame_id, status, stream_control, stream_fault, stream_patches_dropped, stream_points,
    stream_sobel_packets, timestamp_hi, timestamp_lo,
};
use stereocal_hdl::FabricConfig;

use crate::fabric_contract::{config_writes, random_config};
use crate::rng::Rng;
#[cfg(rtl_sim)]
use crate::rtl_fabric::RtlFabric;
use crate::rtl_fabric::{POINT_DEPTH, W0, W1, W2, W3};

/// LINK_OUT on the model's side: every byte its engine sends.
#[derive(Default)]
pub struct Collect(pub Vec<u8>);

impl ByteSink for Collect {
    fn write(&mut self, bytes: &[u8]) {
        self.0.extend_from_slice(bytes);
    }
}

/// The device model at the RTL's sizes, its engine on a collecting link.
pub type StreamModel = FabricDevice<RegisterFrontEnd<W0, W1, W2, W3, POINT_DEPTH>, W0, Collect>;

/// The engine's registers after a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// STREAM_POINTS.
    pub points: u32,
    /// STREAM_SOBEL_PACKETS.
    pub sobel_packets: u32,
    /// STREAM_PATCHES_DROPPED.
    pub patches_dropped: u32,
    /// STREAM_FAULT.
    pub fault: u32,
}

const COUNTERS: [u16; 4] = [
    stream_points::OFFSET,
    stream_sobel_packets::OFFSET,
    stream_patches_dropped::OFFSET,
    stream_fault::OFFSET,
];

/// One frame of the co-simulation: what to send and how.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The configuration the driver writes.
    pub config: FabricConfig,
    /// The camera's image, `config.width` x `config.height`.
    pub image: Vec<u8>,
    /// STREAM_CONTROL, FRAME_ID, TIMESTAMP_LO, TIMESTAMP_HI, CONTROL (enable, then arm).
    pub writes: Vec<(u16, u32)>,
}

impl Frame {
    /// A random frame: a valid configuration (both Sobel modes, batches, segments and
    /// thresholds of every size), a camera number, a frame number, a timestamp and parity or
    /// not; blobs on texture mostly, else noise.
    pub fn random(r: &mut Rng) -> Self {
        let config = random_config(r);
        let (w, h) = (usize::from(config.width), usize::from(config.height));
        let image = if r.chance(750) {
            r.blob_image(w, h)
        } else {
            (0..w * h).map(|_| r.bits() as u8).collect()
        };
        let camera = [0, 1, 1, 2, 255][r.below(5) as usize];
        let fec = r.chance(300);
        let timestamp = r.bits();
        let mut writes = config_writes(&config);
        writes.extend([
            (
                stream_control::OFFSET,
                stream_control::ENABLE.mask()
                    | if fec { stream_control::FEC.mask() } else { 0 }
                    | (camera << stream_control::CAMERA.mask().trailing_zeros()),
            ),
            (frame_id::OFFSET, r.bits() as u32),
            (timestamp_lo::OFFSET, timestamp as u32),
            (timestamp_hi::OFFSET, (timestamp >> 32) as u32),
            (control::OFFSET, control::ENABLE.mask()),
            (
                control::OFFSET,
                control::ENABLE.mask() | control::FRAME_ARM.mask(),
            ),
        ]);
        Self {
            config,
            image,
            writes,
        }
    }

    fn beat(&self, i: usize) -> Beat {
        Beat {
            data: self.image[i],
            sof: i == 0,
            eol: (i + 1) % usize::from(self.config.width) == 0,
        }
    }
}

/// The model's bytes and registers for `frame`: the writes, the pixels back to back, then
/// STATUS polled until BUSY falls.
pub fn model_frame(model: &mut StreamModel, frame: &Frame) -> (Vec<u8>, Counters) {
    for &(offset, value) in &frame.writes {
        model.clock(None, Some(Access::Write(offset, value)));
    }
    let mut i = 0;
    while i < frame.image.len() {
        if model.clock(Some(frame.beat(i)), None).ready {
            i += 1;
        }
    }
    let limit = 1000 * frame.image.len();
    let mut clocks = 0;
    while model
        .clock(None, Some(Access::Read(status::OFFSET)))
        .read
        .is_some_and(|word| status::BUSY.extract(word) != 0)
    {
        clocks += 1;
        assert!(clocks < limit, "the model's BUSY stays 1");
    }
    let read = |model: &mut StreamModel, offset| {
        model
            .clock(None, Some(Access::Read(offset)))
            .read
            .unwrap_or_default()
    };
    let [points, sobel_packets, patches_dropped, fault] = COUNTERS.map(|o| read(model, o));
    (
        std::mem::take(&mut model.link_mut().0),
        Counters {
            points,
            sobel_packets,
            patches_dropped,
            fault,
        },
    )
}

/// How the RTL side is clocked.
#[derive(Clone, Copy, Debug)]
pub struct Clocking {
    /// Clocks per pixel clock (PIXEL_IN's pix_ce is 1 on one clock in `ratio`).
    pub ratio: u64,
    /// Pixel clocks without a pixel after each line (a sensor's horizontal blanking).
    pub line_blank: u64,
    /// Per mille of clocks on which LINK_OUT is not ready.
    pub link_stalls: u64,
}

/// What the RTL did with a frame.
#[derive(Clone, Debug)]
pub struct RtlRun {
    /// LINK_OUT's bytes, from the first write to BUSY's fall.
    pub bytes: Vec<u8>,
    /// The engine's registers.
    pub counters: Counters,
    /// Clocks from the first write to BUSY's fall.
    pub clocks: u64,
}

/// The RTL's bytes and registers for `frame`: the writes one per clock, the pixels one per
/// pixel clock with `line_blank` pixel clocks after each line, then STATUS read on every
/// clock until BUSY falls.
#[cfg(rtl_sim)]
pub fn rtl_frame(rtl: &mut RtlFabric, frame: &Frame, clocking: Clocking, r: &mut Rng) -> RtlRun {
    let mut bytes = Vec::new();
    let clock = std::cell::Cell::new(0u64);
    let mut step = |rtl: &mut RtlFabric, pixel: Option<Beat>, access: Option<Access>| {
        let ce = clock.get() % clocking.ratio == 0;
        clock.set(clock.get() + 1);
        let ready = !r.chance(clocking.link_stalls);
        let (shown, sent) = rtl.clock_linked(pixel.filter(|_| ce), access, ce, ready);
        bytes.extend(sent);
        (shown, ce)
    };
    for &(offset, value) in &frame.writes {
        step(rtl, None, Some(Access::Write(offset, value)));
    }
    let (mut i, mut blank) = (0, 0);
    while i < frame.image.len() {
        if blank > 0 {
            let (_, ce) = step(rtl, None, None);
            blank -= u64::from(ce);
            continue;
        }
        let (shown, ce) = step(rtl, Some(frame.beat(i)), None);
        if ce && shown.ready {
            i += 1;
            if i % usize::from(frame.config.width) == 0 {
                blank = clocking.line_blank;
            }
        }
    }
    let limit = 2_000 * frame.image.len() as u64;
    loop {
        let (shown, _) = step(rtl, None, Some(Access::Read(status::OFFSET)));
        if shown
            .read
            .is_some_and(|word| status::BUSY.extract(word) == 0)
        {
            break;
        }
        assert!(clock.get() < limit, "the RTL's BUSY stays 1");
    }
    let [points, sobel_packets, patches_dropped, fault] = COUNTERS.map(|o| {
        step(rtl, None, Some(Access::Read(o)))
            .0
            .read
            .unwrap_or_default()
    });
    RtlRun {
        bytes,
        counters: Counters {
            points,
            sobel_packets,
            patches_dropped,
            fault,
        },
        clocks: clock.get(),
    }
}

/// A new device model (after power-up).
pub fn stream_model() -> Box<StreamModel> {
    Box::new(FabricDevice::with_link(
        RegisterFrontEnd::new(),
        Collect::default(),
    ))
}
