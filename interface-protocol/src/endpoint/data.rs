//! The surface data channels: slices of one wire type with a `StepHeader`, written in place into a
//! loan and read in place from the sample (DESIGN §3, lockstep).

use super::{ipc_err, wait_for, ProtocolError, Timeouts};
use crate::liveness::Watch;
use crate::messages::{NodeLoad, NodeState, StepHeader, SurfaceElement};
use crate::{services, shm};
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::BackpressureAction;
use iceoryx2::prelude::{ipc, AllocationStrategy, Node, ZeroCopySend};
use std::fmt::Debug;
use std::time::{Duration, Instant};

/// Wire types whose every bit pattern is a valid value (only integers and `f64` inside).
///
/// # Safety
/// Implement only for `#[repr(C)]` types made of integers, floats and arrays of them.
pub unsafe trait Plain: Debug + ZeroCopySend + Copy + 'static {}
// SAFETY: each is `#[repr(C)]` of f64 arrays, u32/u8 arrays and f64 (see `messages`).
unsafe impl Plain for NodeState {}
// SAFETY: as above.
unsafe impl Plain for NodeLoad {}
// SAFETY: as above.
unsafe impl Plain for SurfaceElement {}

/// Samples a subscriber may buffer: lockstep allows one in flight (the topology's history fits).
const BUFFER: usize = 1;

/// Opens one surface service with the settings every side uses.
pub(crate) fn open_service<T: Plain>(
    node: &Node<ipc::Service>,
    run_id: &str,
    name: &str,
    history: usize,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [T], StepHeader>,
    ProtocolError,
> {
    node.service_builder(&services::service_name(run_id, name)?)
        .publish_subscribe::<[T]>()
        .user_header::<StepHeader>()
        .enable_safe_overflow(false)
        .history_size(history)
        .subscriber_max_buffer_size(BUFFER)
        .max_publishers(1)
        .open_or_create()
        .map_err(|e| ipc_err(&format!("cannot open the service {name}"), e))
}

/// A publisher of slices of `T`.
pub(crate) struct SliceWriter<T: Plain> {
    publisher: Publisher<ipc::Service, [T], StepHeader>,
    name: &'static str,
    /// Largest slice whose memory was checked in `/dev/shm`.
    checked: usize,
}

impl<T: Plain> SliceWriter<T> {
    pub(crate) fn create(
        node: &Node<ipc::Service>,
        run_id: &str,
        name: &'static str,
        history: usize,
        initial_len: usize,
        timeouts: Timeouts,
    ) -> Result<Self, ProtocolError> {
        let initial_len = initial_len.max(1);
        check_room::<T>(initial_len, name)?;
        let publisher = open_service::<T>(node, run_id, name, history)?
            .publisher_builder()
            .initial_max_slice_len(initial_len)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(1)
            // Lockstep: a full reader buffer means the reader is behind; retry until the delivery
            // deadline, then fail the send instead of dropping or spinning forever.
            .set_backpressure_handler(retry_until(timeouts.delivery))
            .create()
            .map_err(|e| ipc_err(&format!("cannot create the publisher of {name}"), e))?;
        Ok(SliceWriter { publisher, name, checked: initial_len })
    }

    /// Loans `n` elements, lets `fill` write them in place, stamps the header and sends.
    pub(crate) fn publish<R>(
        &mut self,
        mut header: StepHeader,
        n: usize,
        fill: impl FnOnce(&mut [T]) -> R,
    ) -> Result<R, ProtocolError> {
        if n > self.checked {
            check_room::<T>(n.next_power_of_two(), self.name)?;
            self.checked = n.next_power_of_two();
        }
        let sample = self
            .publisher
            .loan_slice_uninit(n)
            .map_err(|e| ipc_err(&format!("cannot loan {n} elements of {}", self.name), e))?;
        // SAFETY: the loan lies in a shared-memory segment that iceoryx2 mapped from a tmpfs file;
        // its bytes were initialized by the kernel (zero fill) or by earlier samples, and `T:
        // Plain` makes every bit pattern a valid `T`.
        let mut sample = unsafe { sample.assume_init() };
        let out = fill(sample.payload_mut());
        header.count = n as u64;
        *sample.user_header_mut() = header;
        sample.send().map_err(|e| {
            ProtocolError::Delivery(format!(
                "cannot deliver {} for step {} (t = {}): {e:?}; the reader has not consumed the \
                 previous sample (lockstep broken) or is gone",
                self.name, header.step, header.time
            ))
        })?;
        Ok(out)
    }
}

/// A backpressure handler that retries for `delivery`, then fails the send
/// (`SendError::UnableToDeliver`).
pub(crate) fn retry_until(
    delivery: Duration,
) -> impl Fn(&iceoryx2::port::BackpressureInfo) -> BackpressureAction + Send + 'static {
    move |info| {
        if info.elapsed_time < delivery {
            std::thread::sleep(Duration::from_micros(200));
            BackpressureAction::Retry
        } else {
            BackpressureAction::DiscardDataAndFail
        }
    }
}

/// Checks that `/dev/shm` can hold the publisher's pool for slices of `n` elements.
fn check_room<T>(n: usize, name: &str) -> Result<(), ProtocolError> {
    let bytes = (n * std::mem::size_of::<T>() + 4096) as u64 * (BUFFER as u64 + 2);
    shm::ensure_capacity(bytes, &format!("the {name} buffer of {n} elements"))
}

/// A subscriber of slices of `T`.
pub(crate) struct SliceReader<T: Plain> {
    subscriber: Subscriber<ipc::Service, [T], StepHeader>,
    name: &'static str,
}

impl<T: Plain> SliceReader<T> {
    pub(crate) fn create(
        node: &Node<ipc::Service>,
        run_id: &str,
        name: &'static str,
        history: usize,
    ) -> Result<Self, ProtocolError> {
        let subscriber = open_service::<T>(node, run_id, name, history)?
            .subscriber_builder()
            .buffer_size(BUFFER)
            .create()
            .map_err(|e| ipc_err(&format!("cannot create the subscriber of {name}"), e))?;
        Ok(SliceReader { subscriber, name })
    }

    /// Waits (deadline `timeout`) for the next sample and hands header and slice to `read`.
    pub(crate) fn read<R>(
        &self,
        listener: &Listener<ipc::Service>,
        watch: &Watch,
        timeout: Duration,
        waited: &mut Duration,
        read: impl FnOnce(&StepHeader, &[T]) -> R,
    ) -> Result<R, ProtocolError> {
        let start = Instant::now();
        let name = self.name;
        let sample =
            wait_for(listener, watch, start + timeout, &|| format!("a sample on {name}"), || {
                self.subscriber
                    .receive()
                    .map_err(|e| ipc_err(&format!("cannot receive on {name}"), e))
            });
        *waited += start.elapsed();
        let sample = sample?;
        let header = *sample.user_header();
        let payload = sample.payload();
        if header.count != payload.len() as u64 {
            return Err(ProtocolError::Delivery(format!(
                "{name}: the header says {} elements, the sample holds {}",
                header.count,
                payload.len()
            )));
        }
        Ok(read(&header, payload))
    }

    /// The newest sample if one is waiting, without blocking.
    pub(crate) fn try_read<R>(
        &self,
        read: impl FnOnce(&StepHeader, &[T]) -> R,
    ) -> Result<Option<R>, ProtocolError> {
        let name = self.name;
        let sample = self
            .subscriber
            .receive()
            .map_err(|e| ipc_err(&format!("cannot receive on {name}"), e))?;
        Ok(sample.map(|s| read(s.user_header(), s.payload())))
    }
}

/// Wakes the peer after a send.
pub(crate) fn wake(notifier: &Notifier<ipc::Service>) {
    let _ = notifier.notify();
}
