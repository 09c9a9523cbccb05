//! Sending a freshly written sample on the writing thread, the event loop
//! keeping everything else (see `writer_thread_send_design.md`).
//!
//! A written sample normally reaches the network through the event-loop
//! thread: `DataWriter::write` admits it to the [`WriterSendBuffer`] and rings
//! the doorbell, and the event loop's `Writer::process_pending` sends it. When
//! nothing is pending and every matched reader has a resolved unicast IPv4
//! route, [`Transmit::send_now`] sends it from the writing thread instead, as
//! the event loop's aggregated path would for one sample (INFO_TS if stamped,
//! DATA to every reader, one HEARTBEAT for a reliable writer), and the doorbell
//! is not rung. Otherwise the caller rings the doorbell as before.
//!
//! Rules that keep the two threads correct:
//! - the event loop calls into a `Writer` only with the writer's transmit lock
//!   held (`Writer::with_transmit`), and copies `last_sent` in and out under
//!   it; the writing thread only `try_lock`s, so an application thread never
//!   waits for the event loop;
//! - a sample is sent here only if it is the next one to send
//!   (`last_sent + 1`) with no fragment in progress, so samples leave in
//!   sequence order;
//! - every HEARTBEAT count is taken and sent under the transmit lock, so counts
//!   reach readers in increasing order (a reader ignores one that is not above
//!   the last it saw);
//! - lock order: the transmit lock, then the route snapshot's lock, then the
//!   send buffer's lock.

use std::{
  net::{SocketAddr, UdpSocket},
  sync::{
    atomic::{AtomicBool, AtomicI32, Ordering},
    Arc, Mutex, MutexGuard, PoisonError, TryLockError,
  },
};

#[allow(unused_imports)]
use log::{debug, error, trace, warn};
use speedy::Endianness;

use crate::{
  network::udp_sender::send_datagram,
  rtps::{outbound::SendOutcome, writer_send_buffer::WriterSendBuffer, MessageBuilder},
  structure::{
    guid::{EntityId, GUID},
    sequence_number::SequenceNumber,
  },
};

/// Where and how the writing thread may send: refreshed by the `Writer`
/// whenever its matched readers or their routes change, `None` whenever the
/// event loop must send everything.
#[derive(Debug)]
pub(crate) struct FastRoute {
  /// The participant's unicast sender socket (a duplicate of the event loop's,
  /// non-blocking like it).
  pub socket: Arc<UdpSocket>,
  /// Set while the event loop holds queued control datagrams for that socket:
  /// bulk data then waits for them (strict priority), so the writing thread
  /// leaves the sample to the event loop.
  pub control_backlog: Arc<AtomicBool>,
  /// Every matched reader's unicast destination, each once.
  pub destinations: Vec<SocketAddr>,
  /// The largest serialized payload sent unfragmented (the event loop's own
  /// limit for the aggregated path, so the two threads never disagree about
  /// fragmenting).
  pub max_payload: usize,
  pub writer_guid: GUID,
  pub endianness: Endianness,
  /// A reliable writer: the datagram carries a HEARTBEAT.
  pub reliable: bool,
}

/// What the event loop and the writing thread share beyond the samples.
#[derive(Debug)]
pub(crate) struct Transmit {
  state: Mutex<TransmitState>,
  route: Mutex<Option<Arc<FastRoute>>>,
  heartbeat_count: AtomicI32,
}

/// The send progress, under the transmit lock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TransmitState {
  /// Samples up to this one have been sent (or skipped).
  pub last_sent: SequenceNumber,
  /// No fragmented sample is half sent.
  pub cursor_fresh: bool,
}

impl Default for Transmit {
  fn default() -> Self {
    Self {
      state: Mutex::new(TransmitState {
        last_sent: SequenceNumber::zero(),
        cursor_fresh: true,
      }),
      route: Mutex::new(None),
      heartbeat_count: AtomicI32::new(1),
    }
  }
}

impl Transmit {
  /// The transmit lock, waiting for it (the event loop's side).
  pub fn lock(&self) -> MutexGuard<'_, TransmitState> {
    self.state.lock().unwrap_or_else(PoisonError::into_inner)
  }

  /// The next HEARTBEAT count. Call with the transmit lock held and send the
  /// HEARTBEAT before releasing it.
  pub fn next_heartbeat_count(&self) -> i32 {
    self.heartbeat_count.fetch_add(1, Ordering::SeqCst)
  }

  /// Replaces the route snapshot (`None`: the event loop sends everything).
  pub fn set_route(&self, route: Option<FastRoute>) {
    *self.route.lock().unwrap_or_else(PoisonError::into_inner) = route.map(Arc::new);
  }

  #[cfg(test)]
  pub fn route(&self) -> Option<Arc<FastRoute>> {
    self
      .route
      .lock()
      .unwrap_or_else(PoisonError::into_inner)
      .clone()
  }

  /// Sends sample `seq` of `buffer` from the calling thread if it may be sent
  /// here (see the module's documentation). Returns whether it was sent; if
  /// not, the caller rings the doorbell and the event loop sends it.
  pub fn send_now(&self, buffer: &WriterSendBuffer, seq: SequenceNumber) -> bool {
    let mut state = match self.state.try_lock() {
      Ok(state) => state,
      // The event loop is working on this writer: it will also see the sample.
      Err(TryLockError::WouldBlock) => return false,
      Err(TryLockError::Poisoned(poisoned)) => poisoned.into_inner(),
    };
    if !state.cursor_fresh || state.last_sent.plus_1() != seq {
      return false;
    }
    let Some(route) = self
      .route
      .lock()
      .unwrap_or_else(PoisonError::into_inner)
      .clone()
    else {
      return false;
    };
    if route.control_backlog.load(Ordering::Acquire) {
      return false;
    }
    let Some(cc) = buffer.get_by_sn(seq) else {
      return false;
    };
    if cc.write_options.to_single_reader().is_some()
      || cc.data_value.payload_size() > route.max_payload
    {
      return false;
    }

    let mut builder = MessageBuilder::new();
    if let Some(timestamp) = cc.write_options.source_timestamp() {
      builder = builder.ts_msg(route.endianness, Some(timestamp));
    }
    builder = builder.data_msg(
      &cc,
      EntityId::UNKNOWN, // to every reader
      route.writer_guid,
      route.endianness,
      None,
    );
    if route.reliable {
      builder = builder.heartbeat_msg(
        route.writer_guid.entity_id,
        buffer.first_change_sequence_number(),
        seq, // not a later sample another thread may have admitted meanwhile
        self.next_heartbeat_count(),
        route.endianness,
        EntityId::UNKNOWN,
        false, // final_flag: ask for an ACKNACK
        false, // liveliness_flag
      );
    }
    let datagram = match builder
      .add_header_and_build(route.writer_guid.prefix)
      .write_to_vec_fast(route.endianness)
    {
      Ok(datagram) => datagram,
      Err(e) => {
        error!("send_now: cannot serialize the message: {e:?}");
        return false;
      }
    };
    for &destination in &route.destinations {
      match send_datagram(&route.socket, &"send_now: unicast", destination, &datagram) {
        SendOutcome::Sent | SendOutcome::Dropped => {}
        // The event loop sends the sample again to every reader on write
        // readiness; a reader that got it here discards the duplicate.
        SendOutcome::WouldBlock => return false,
      }
    }
    state.last_sent = seq;
    buffer.set_sent_frontier(seq);
    true
  }
}

#[cfg(test)]
pub(crate) mod tests {
  use std::time::Duration as StdDuration;

  use bytes::Bytes;

  use super::*;
  use crate::{
    dds::{
      ddsdata::DDSData,
      with_key::datawriter::{WriteOptions, WriteOptionsBuilder},
    },
    messages::submessages::{
      elements::serialized_payload::SerializedPayload, submessages::WriterSubmessage,
    },
    rtps::{submessage::SubmessageBody, writer_send_buffer::Admission, Message},
    structure::{
      guid::{EntityKind, GuidPrefix},
      time::Timestamp,
    },
    RepresentationIdentifier,
  };

  const PAYLOAD: usize = 200;

  /// A reliable writer's send buffer, a route to one reader socket on loopback.
  struct Bench {
    buffer: WriterSendBuffer,
    reader: UdpSocket,
    guid: GUID,
  }

  impl Bench {
    fn new() -> Self {
      let guid = GUID::new(
        GuidPrefix::new(&[7; 12]),
        EntityId::new([0, 0, 1], EntityKind::WRITER_NO_KEY_USER_DEFINED),
      );
      let buffer = WriterSendBuffer::new(guid, "fast".to_string(), true, false, true, 16, 16, 16);
      let reader = UdpSocket::bind("127.0.0.1:0").unwrap();
      reader
        .set_read_timeout(Some(StdDuration::from_millis(200)))
        .unwrap();
      let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
      socket.set_nonblocking(true).unwrap();
      buffer.transmit().set_route(Some(FastRoute {
        socket: Arc::new(socket),
        control_backlog: Arc::new(AtomicBool::new(false)),
        destinations: vec![reader.local_addr().unwrap()],
        max_payload: 1000,
        writer_guid: guid,
        endianness: Endianness::LittleEndian,
        reliable: true,
      }));
      Self {
        buffer,
        reader,
        guid,
      }
    }

    fn admit(&self, options: WriteOptions, len: usize) -> SequenceNumber {
      admit(&self.buffer, options, len)
    }

    fn send_now(&self, seq: SequenceNumber) -> bool {
      self.buffer.transmit().send_now(&self.buffer, seq)
    }

    fn receive(&self) -> Option<(Vec<i64>, Vec<(i64, i64, i32)>)> {
      let received = received(&self.reader)?;
      assert_eq!(received.writer, self.guid);
      Some((received.data, received.heartbeats))
    }
  }

  /// Admits a sample of `len` bytes to `buffer`.
  pub(crate) fn admit(
    buffer: &WriterSendBuffer,
    options: WriteOptions,
    len: usize,
  ) -> SequenceNumber {
    let data = DDSData::new(SerializedPayload::new(
      RepresentationIdentifier::CDR_LE,
      vec![1; len],
    ));
    match buffer.admit_blocking(options, data, Some(StdDuration::ZERO)) {
      Admission::Admitted(seq) => seq,
      Admission::WouldBlock => panic!("the buffer refused a sample"),
    }
  }

  /// What one datagram carried from a writer.
  pub(crate) struct Received {
    pub writer: GUID,
    /// The DATA submessages' sequence numbers.
    pub data: Vec<i64>,
    /// The HEARTBEATs as (first, last, count).
    pub heartbeats: Vec<(i64, i64, i32)>,
  }

  /// The next datagram on `socket`, `None` if none comes within its timeout.
  /// Every DATA and HEARTBEAT in it must be of one writer, to every reader.
  pub(crate) fn received(socket: &UdpSocket) -> Option<Received> {
    let mut datagram = vec![0; 65536];
    let len = socket.recv(&mut datagram).ok()?;
    let message = Message::read_from_buffer(&Bytes::copy_from_slice(&datagram[..len])).unwrap();
    let prefix = message.header.guid_prefix;
    let mut writer = None;
    let mut data = Vec::new();
    let mut heartbeats = Vec::new();
    for submessage in message.submessages {
      let writer_id = match submessage.body {
        SubmessageBody::Writer(WriterSubmessage::Data(d, _)) => {
          assert_eq!(d.reader_id, EntityId::UNKNOWN);
          data.push(i64::from(d.writer_sn));
          d.writer_id
        }
        SubmessageBody::Writer(WriterSubmessage::Heartbeat(h, _)) => {
          heartbeats.push((i64::from(h.first_sn), i64::from(h.last_sn), h.count));
          h.writer_id
        }
        _ => continue,
      };
      let guid = GUID::new(prefix, writer_id);
      assert_eq!(
        *writer.get_or_insert(guid),
        guid,
        "two writers in one datagram"
      );
    }
    Some(Received {
      writer: writer.expect("no DATA or HEARTBEAT in the datagram"),
      data,
      heartbeats,
    })
  }

  #[test]
  fn the_next_sample_leaves_on_the_writing_thread_with_one_heartbeat() {
    let bench = Bench::new();
    let seq = bench.admit(WriteOptions::default(), PAYLOAD);
    assert!(bench.send_now(seq));
    // One datagram: DATA 1 and a HEARTBEAT announcing 1..=1 with the first count.
    assert_eq!(bench.receive(), Some((vec![1], vec![(1, 1, 1)])));
    assert_eq!(bench.buffer.transmit().lock().last_sent, seq);
    assert_eq!(bench.buffer.sent_frontier(), seq);
    // The event loop's next HEARTBEAT count follows the one sent here.
    assert_eq!(bench.buffer.transmit().next_heartbeat_count(), 2);
    // The next sample goes the same way, in order.
    let next = bench.admit(WriteOptions::default(), PAYLOAD);
    assert!(bench.send_now(next));
    assert_eq!(bench.receive(), Some((vec![2], vec![(1, 2, 3)])));
  }

  #[test]
  fn a_stamped_sample_keeps_its_timestamp() {
    let bench = Bench::new();
    let stamp = Timestamp::now();
    let seq = bench.admit(
      WriteOptionsBuilder::new().source_timestamp(stamp).build(),
      PAYLOAD,
    );
    assert!(bench.send_now(seq));
    let mut datagram = vec![0; 65536];
    let len = bench.reader.recv(&mut datagram).unwrap();
    let message = Message::read_from_buffer(&Bytes::copy_from_slice(&datagram[..len])).unwrap();
    let stamps: Vec<_> = message
      .submessages
      .iter()
      .filter_map(|s| match &s.body {
        SubmessageBody::Interpreter(
          crate::messages::submessages::submessages::InterpreterSubmessage::InfoTimestamp(ts, _),
        ) => Some(ts.timestamp),
        _ => None,
      })
      .collect();
    assert_eq!(stamps, vec![Some(stamp)]);
  }

  #[test]
  fn a_sample_behind_an_unsent_one_waits_for_it() {
    let bench = Bench::new();
    let first = bench.admit(WriteOptions::default(), PAYLOAD);
    let second = bench.admit(WriteOptions::default(), PAYLOAD);
    // Sample 1 is still pending (its writer rang the doorbell): 2 may not pass it.
    assert!(!bench.send_now(second));
    assert_eq!(bench.receive(), None);
    assert!(bench.send_now(first));
    assert!(bench.send_now(second));
    // Each HEARTBEAT announces the samples sent so far, not one admitted but
    // still to be sent (which the reader would request at once).
    assert_eq!(bench.receive(), Some((vec![1], vec![(1, 1, 1)])));
    assert_eq!(bench.receive(), Some((vec![2], vec![(1, 2, 2)])));
    // A sample already sent is not sent again.
    assert!(!bench.send_now(second));
    assert_eq!(bench.receive(), None);
  }

  #[test]
  fn the_event_loop_sends_whatever_the_writing_thread_may_not() {
    let bench = Bench::new();
    let seq = bench.admit(WriteOptions::default(), PAYLOAD);
    let transmit = bench.buffer.transmit();

    // The event loop is working on this writer.
    {
      let _event_loop = transmit.lock();
      assert!(!bench.send_now(seq));
    }
    // A fragmented sample is half sent.
    transmit.lock().cursor_fresh = false;
    assert!(!bench.send_now(seq));
    transmit.lock().cursor_fresh = true;
    // The socket holds queued control datagrams.
    let route = transmit.route().unwrap();
    route.control_backlog.store(true, Ordering::Release);
    assert!(!bench.send_now(seq));
    route.control_backlog.store(false, Ordering::Release);
    // No route (a reader without a resolved unicast route, for one).
    transmit.set_route(None);
    assert!(!bench.send_now(seq));
    assert_eq!(bench.receive(), None);
    assert_eq!(transmit.lock().last_sent, SequenceNumber::zero());
    assert_eq!(bench.buffer.sent_frontier(), SequenceNumber::zero());
    // None of these took a HEARTBEAT count.
    assert_eq!(transmit.next_heartbeat_count(), 1);
  }

  #[test]
  fn a_sample_for_one_reader_or_one_to_fragment_is_left_to_the_event_loop() {
    let bench = Bench::new();
    let reader = GUID::new(
      GuidPrefix::new(&[9; 12]),
      EntityId::new([0, 0, 2], EntityKind::READER_NO_KEY_USER_DEFINED),
    );
    let single = bench.admit(
      WriteOptionsBuilder::new().to_single_reader(reader).build(),
      PAYLOAD,
    );
    assert!(!bench.send_now(single));
    // What the event loop does with it.
    bench.buffer.transmit().lock().last_sent = single;
    // The route's limit counts the serialized payload: these bytes and the 4-byte
    // representation header.
    let large = bench.admit(WriteOptions::default(), 997);
    assert!(!bench.send_now(large));
    assert_eq!(bench.receive(), None);
    // At the limit it still fits.
    bench.buffer.transmit().lock().last_sent = large;
    let fits = bench.admit(WriteOptions::default(), 996);
    assert!(bench.send_now(fits));
    assert_eq!(bench.receive().map(|(data, _)| data), Some(vec![3]));
  }
}
