//! A device that runs in its own thread, as a real head runs beside the host.
//!
//! The in-process device computes a frame pair when it is handed one and the host decodes and
//! estimates when the bytes are back; called in turn, the two never overlap. A camera head
//! does not wait for the host: it works on the next pair while the host works on the last.
//! [`Threaded`] gives the in-process device that shape. Requests and pairs go to a worker
//! thread in order; the bytes each one produces collect in a queue that [`Link::recv`] reads,
//! so a session can submit pair `n + 1` before it reads pair `n` ([`FrameInput::lookahead`]).
//!
//! The wrapped device must only speak when spoken to, as the in-process one does: the worker
//! collects its bytes after each request or pair, so a byte it sent unasked would wait for
//! the next one. For the same reason a receive with nothing queued and nothing in progress is
//! a timeout at once: nothing can arrive by waiting.

use std::collections::VecDeque;
use std::sync::mpsc::{self, Sender};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::{FrameInput, Link, LinkError};

/// Pairs a session may have in the worker beyond the one it is reading.
const LOOKAHEAD: usize = 1;

/// What the worker is asked to do, in order.
enum Job {
    Send(Vec<u8>),
    Pair {
        left: Vec<u8>,
        right: Vec<u8>,
        timestamp_us: u64,
    },
}

/// What the worker hands back.
#[derive(Default)]
struct Output {
    chunks: VecDeque<Vec<u8>>,
    /// Bytes of the front chunk already read.
    read: usize,
    /// Jobs sent and not finished.
    in_progress: usize,
    /// The device's first failure; reported by the next `recv`, after the bytes before it.
    error: Option<LinkError>,
    /// The worker has stopped (its thread ended or panicked).
    stopped: bool,
    /// The last chunk read, for the worker to fill again.
    spare: Option<Vec<u8>>,
}

#[derive(Default)]
struct Shared {
    output: Mutex<Output>,
    ready: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Output> {
        // A worker that panicked holding the lock left consistent data (it only appends).
        self.output.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// `D` in a worker thread (see the module documentation).
pub struct Threaded {
    jobs: Option<Sender<Job>>,
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
    timeout: Duration,
    name: String,
}

impl Threaded {
    /// Moves `device` into a new worker thread named `name` (the link's name in errors).
    pub fn new<D: Link + FrameInput + 'static>(device: D, name: &str) -> Result<Self, LinkError> {
        let timeout = device.answer_timeout();
        let shared = Arc::new(Shared::default());
        let (jobs, inbox) = mpsc::channel::<Job>();
        let worker_shared = Arc::clone(&shared);
        let worker = std::thread::Builder::new()
            .name(format!("{name} device"))
            .spawn(move || serve(device, inbox, &worker_shared))
            .map_err(|source| LinkError::Open {
                link: name.into(),
                source,
            })?;
        Ok(Self {
            jobs: Some(jobs),
            shared,
            worker: Some(worker),
            timeout,
            name: name.into(),
        })
    }

    fn post(&mut self, job: Job) -> Result<(), LinkError> {
        let closed = || LinkError::Closed {
            link: self.name.clone(),
        };
        let jobs = self.jobs.as_ref().ok_or_else(closed)?;
        let mut out = self.shared.lock();
        if out.stopped {
            return Err(closed());
        }
        out.in_progress += 1;
        drop(out);
        jobs.send(job).map_err(|_| closed())
    }
}

/// The worker: runs each job, then collects what the device sent.
fn serve<D: Link + FrameInput>(mut device: D, inbox: mpsc::Receiver<Job>, shared: &Shared) {
    for job in inbox {
        let result = match job {
            Job::Send(bytes) => device.send(&bytes),
            Job::Pair {
                left,
                right,
                timestamp_us,
            } => device.submit_pair(&left, &right, timestamp_us),
        };
        // A buffer the host has read, so its allocation serves again.
        let mut bytes = shared.lock().spare.take().unwrap_or_default();
        bytes.clear();
        let error = result.and_then(|()| device.take_sent(&mut bytes)).err();
        let mut out = shared.lock();
        if !bytes.is_empty() {
            out.chunks.push_back(bytes);
        }
        if out.error.is_none() {
            out.error = error;
        }
        out.in_progress = out.in_progress.saturating_sub(1);
        drop(out);
        shared.ready.notify_all();
    }
    shared.lock().stopped = true;
    shared.ready.notify_all();
}

impl Link for Threaded {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.post(Job::Send(bytes.to_vec()))
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        let start = Instant::now();
        let mut out = self.shared.lock();
        loop {
            let Output { chunks, read, .. } = &mut *out;
            if let Some(front) = chunks.front() {
                let pending = front.get(*read..).unwrap_or_default();
                let n = pending.len().min(buf.len());
                buf[..n].copy_from_slice(&pending[..n]);
                *read += n;
                if *read >= front.len() {
                    out.spare = chunks.pop_front();
                    out.read = 0;
                }
                return Ok(n);
            }
            if let Some(e) = out.error.take() {
                return Err(e);
            }
            let now = Instant::now();
            if out.in_progress == 0 || out.stopped || now >= deadline {
                return Err(LinkError::Timeout {
                    link: self.name.clone(),
                    waited: now - start,
                });
            }
            out = self
                .shared
                .ready
                .wait_timeout(out, deadline - now)
                .unwrap_or_else(|e| e.into_inner())
                .0;
        }
    }

    fn answer_timeout(&self) -> Duration {
        self.timeout
    }
}

impl FrameInput for Threaded {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        self.post(Job::Pair {
            left: left.to_vec(),
            right: right.to_vec(),
            timestamp_us,
        })
    }

    fn lookahead(&self) -> usize {
        LOOKAHEAD
    }
}

impl Drop for Threaded {
    /// Closes the job queue and waits for the worker to finish what it was given.
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(worker) = self.worker.take() {
            let _ = worker.join();
        }
    }
}
