//! The fabric's PIXEL_IN stream port, seen from whoever feeds it.

/// Pixels offered on PIXEL_IN (the map's `[[port]] PIXEL_IN`), one per clock in raster
/// order, and clocks on which it is idle.
///
/// On a board the camera drives the port and the soft-core never sees a pixel; where the
/// frames come from elsewhere (the host's in-process device, the frame-grabber region under
/// QEMU) the program offers them through this trait, and a software fabric takes them as
/// its port would. A pixel offered while the port is not ready is lost, as a camera's would
/// be: the fabric's registers say whether the frame was taken.
pub trait PixelIn {
    /// Offers `pixels`, one per clock; the first carries SOF when `start_of_frame`.
    fn push(&mut self, pixels: &[u8], start_of_frame: bool);

    /// `clocks` clocks on which PIXEL_IN holds no pixel (blanking).
    fn idle(&mut self, clocks: u32);
}

impl<P: PixelIn + ?Sized> PixelIn for &mut P {
    fn push(&mut self, pixels: &[u8], start_of_frame: bool) {
        (**self).push(pixels, start_of_frame)
    }

    fn idle(&mut self, clocks: u32) {
        (**self).idle(clocks)
    }
}
