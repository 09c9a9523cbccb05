use std::marker::PhantomData;

use serde::{Deserialize, Serialize};
#[allow(unused_imports)]
use log::{debug, error, info, warn};
use rustdds::{bytes::Bytes, rpc::*, serialization::deserialize_from_cdr_with_rep_id, *};

use crate::{
  error::{ReadError, ReadResult, WriteError, WriteResult},
  message::Message,
  message_info::MessageInfo,
};
use super::{RmwRequestId, ServiceMapping};

// trait Wrapper is for interfacing to Service-specific (De)SerializerAdapter.
// These adapters are essentially pass-through, and do no actual serialization.
// (De)Serialization is done in Wrappers, because they know which ServiceMapping
// to apply, unlike (De)Serializer or their adapters. ServiceMapping must be
// known in order to decode or generate the wire representation.
pub(super) trait Wrapper {
  fn from_bytes_and_ri(input_bytes: &[u8], encoding: RepresentationIdentifier) -> Self;
  fn bytes(&self) -> Bytes;
}

pub(crate) struct RequestWrapper<R> {
  serialized_message: Bytes,
  encoding: RepresentationIdentifier,
  phantom: PhantomData<R>,
}

impl<R: Message> Wrapper for RequestWrapper<R> {
  fn from_bytes_and_ri(input_bytes: &[u8], encoding: RepresentationIdentifier) -> Self {
    RequestWrapper {
      serialized_message: Bytes::copy_from_slice(input_bytes), // cloning here
      encoding,
      phantom: PhantomData,
    }
  }
  fn bytes(&self) -> Bytes {
    self.serialized_message.clone()
  }
}

impl<R: Message> RequestWrapper<R> {
  // This will decode the RequestWrapper to Request in Server
  pub(super) fn unwrap(
    &self,
    service_mapping: ServiceMapping,
    message_info: &MessageInfo,
  ) -> ReadResult<(RmwRequestId, R)> {
    match service_mapping.of_writer(&message_info.publisher_gid()) {
      ServiceMapping::Basic => {
        // 1. decode "RequestHeader" and
        // 2. decode Request
        let mut bytes = self.serialized_message.clone(); // ref copy only
        let (header, header_size) =
          deserialize_from_cdr_with_rep_id::<BasicRequestHeader>(&bytes, self.encoding)?;
        if bytes.len() < header_size {
          read_error_deserialization!("Service request too short")
        } else {
          let _header_bytes = bytes.split_off(header_size);
          let (request, _request_bytes) =
            deserialize_from_cdr_with_rep_id::<R>(&bytes, self.encoding)?;
          Ok((RmwRequestId::from(header.request_id), request))
        }
      }
      ServiceMapping::Enhanced => {
        // Enhanced mode does not use any header in the DDS payload.
        // Therefore, we use a wrapper that is identical to the payload.
        let (request, _request_bytes) =
          deserialize_from_cdr_with_rep_id::<R>(&self.serialized_message, self.encoding)?;
        let mut rmw_req_id = message_info.related_request_id()
            .unwrap_or_else(|| {
              // Without a related sample identity in the inline QoS, the request
              // is named by its own sample identity, as RPC over DDS specifies.
              // Not a fault: rmw_fastrtps's clients add the parameter (naming
              // their reply reader), a RustDDS client does not, so every request
              // of a RustDDS client takes this path.
              let backup_identity = RmwRequestId {
                writer_gid: message_info.publisher_gid(),
                sequence_number: message_info.sequence_number(),
              };
              debug!("RequestWrapper::unwrap: related_sample_identity missing. Using sample_identity = {backup_identity:?}");
              backup_identity
            });

        // Logic added for eProsima FastDDS compatibility:
        //
        // If the SequenceNumber in related_sample_identity (presumable from
        // inline QoS) is SEQUENCENUMBER_UNKNOWN, then it cannot refer
        // to a real and valid DATA submessage. We patch the situation
        // by using the actual SequenceNumber of the Request DATA
        // submessage.
        //
        // Maybe FastDDS just forgets to set the field in
        // RELATED_SAMPLE_IDENTITY inline QoS parameter?
        if rmw_req_id.sequence_number == i64::from(SequenceNumber::UNKNOWN) {
          rmw_req_id.sequence_number = message_info.sequence_number();
        }

        Ok((rmw_req_id, request))
      }
      ServiceMapping::Cyclone => cyclone_unwrap::<R>(
        self.serialized_message.clone(),
        GUID::from(message_info.publisher_gid()),
        self.encoding,
      ),
      ServiceMapping::Auto => unreachable!("of_writer resolves Auto"),
    }
  }

  // Client creates new RequestWrappers from Requests
  pub(super) fn new(
    service_mapping: ServiceMapping,
    r_id: RmwRequestId,
    encoding: RepresentationIdentifier,
    request: R,
  ) -> WriteResult<Self, ()> {
    let mut ser_buffer: Vec<u8> = Vec::with_capacity(std::mem::size_of::<R>() * 3 / 2);

    // First, write header (the client resolves Auto before; unresolved, it is
    // Enhanced)
    match service_mapping.for_servers(std::iter::empty()) {
      ServiceMapping::Basic => {
        let basic_header = BasicRequestHeader::new(r_id.into());
        serialization::to_writer_with_rep_id(&mut ser_buffer, &basic_header, encoding)?;
      }
      ServiceMapping::Enhanced => {
        // This mapping does not use any header, so nothing to do here.
      }
      ServiceMapping::Cyclone => {
        let cyclone_header = CycloneHeader::new(r_id);
        serialization::to_writer_with_rep_id(&mut ser_buffer, &cyclone_header, encoding)?;
      }
      ServiceMapping::Auto => unreachable!("for_servers resolves Auto"),
    }
    // Second, write request
    serialization::to_writer_with_rep_id(&mut ser_buffer, &request, encoding)?;
    // Ok, assemble result
    Ok(RequestWrapper {
      serialized_message: Bytes::from(ser_buffer),
      encoding,
      phantom: PhantomData,
    })
  }
}

pub(crate) struct ResponseWrapper<R> {
  serialized_message: Bytes,
  encoding: RepresentationIdentifier,
  phantom: PhantomData<R>,
}

impl<R: Message> Wrapper for ResponseWrapper<R> {
  fn from_bytes_and_ri(input_bytes: &[u8], encoding: RepresentationIdentifier) -> Self {
    ResponseWrapper {
      serialized_message: Bytes::copy_from_slice(input_bytes), // cloning here
      encoding,
      phantom: PhantomData,
    }
  }
  fn bytes(&self) -> Bytes {
    self.serialized_message.clone()
  }
}

impl<R: Message> ResponseWrapper<R> {
  // Client decodes ResponseWrapper to Response
  // message_info is from Server's response message
  pub(super) fn unwrap(
    &self,
    service_mapping: ServiceMapping,
    message_info: MessageInfo,
    client_guid: GUID,
  ) -> ReadResult<(RmwRequestId, R)> {
    match service_mapping.of_writer(&message_info.publisher_gid()) {
      ServiceMapping::Basic => {
        let mut bytes = self.serialized_message.clone(); // ref copy only
        let (header, header_size) =
          deserialize_from_cdr_with_rep_id::<BasicReplyHeader>(&bytes, self.encoding)?;
        if bytes.len() < header_size {
          read_error_deserialization!("Service response too short")
        } else {
          let _header_bytes = bytes.split_off(header_size);
          let (response, _bytes) = deserialize_from_cdr_with_rep_id::<R>(&bytes, self.encoding)?;
          Ok((RmwRequestId::from(header.related_request_id), response))
        }
      }
      ServiceMapping::Enhanced => {
        // Enhanced mode does not use any header in the DDS payload.
        // Therefore, we use a wrapper that is identical to the payload.
        let (response, _response_bytes) =
          deserialize_from_cdr_with_rep_id::<R>(&self.serialized_message, self.encoding)?;
        let related_sample_identity = match message_info.related_request_id() {
          Some(rsi) => rsi,
          None => {
            return read_error_deserialization!(
              "ServiceMapping=Enhanced, but response message did not have related_sample_identity parameter!"
            );
          }
        };
        Ok((related_sample_identity, response))
      }
      ServiceMapping::Cyclone => {
        // On the client, the upper half of the client GUID comes from local
        // client state (our own GUID); the lower half is carried in the Cyclone
        // header and reassembled inside cyclone_unwrap.
        cyclone_unwrap::<R>(self.serialized_message.clone(), client_guid, self.encoding)
      }
      ServiceMapping::Auto => unreachable!("of_writer resolves Auto"),
    }
  }

  // Server creates new ResponseWrapper from Response
  pub(super) fn new(
    service_mapping: ServiceMapping,
    r_id: RmwRequestId,
    encoding: RepresentationIdentifier,
    response: R,
  ) -> WriteResult<Self, ()> {
    let mut ser_buffer: Vec<u8> = Vec::with_capacity(std::mem::size_of::<R>() * 3 / 2);
    match service_mapping.of_reply(&r_id) {
      ServiceMapping::Basic => {
        let basic_header = BasicReplyHeader::new(r_id.into());
        serialization::to_writer_with_rep_id(&mut ser_buffer, &basic_header, encoding)?;
      }
      ServiceMapping::Enhanced => {
        // No header, nothing to write here.
      }
      ServiceMapping::Cyclone => {
        let cyclone_header = CycloneHeader::new(r_id);
        serialization::to_writer_with_rep_id(&mut ser_buffer, &cyclone_header, encoding)?;
      }
      ServiceMapping::Auto => unreachable!("of_reply resolves Auto"),
    }
    serialization::to_writer_with_rep_id(&mut ser_buffer, &response, encoding)?;
    let serialized_message = Bytes::from(ser_buffer);
    Ok(ResponseWrapper {
      serialized_message,
      encoding,
      phantom: PhantomData,
    })
  }
}

// Basic mode header is specified in
// RPC over DDS Section "7.5.1.1.1 Common Types"
#[derive(Serialize, Deserialize)]
pub struct BasicRequestHeader {
  // "struct RequestHeader":
  request_id: SampleIdentity,
  instance_name: String, // This is apparently not used: Always sent as empty string.
}
impl BasicRequestHeader {
  fn new(request_id: SampleIdentity) -> Self {
    BasicRequestHeader {
      request_id,
      instance_name: "".to_string(),
    }
  }
}
impl Message for BasicRequestHeader {}

#[derive(Serialize, Deserialize)]
pub struct BasicReplyHeader {
  // "struct ReplyHeader":
  related_request_id: SampleIdentity,
  remote_exception_code: u32, /* It is uncertain if this is ever used. Transmitted as zero
                               * ("REMOTE_EX_OK"). */
}
impl BasicReplyHeader {
  fn new(related_request_id: SampleIdentity) -> Self {
    BasicReplyHeader {
      related_request_id,
      remote_exception_code: 0,
    }
  }
}
impl Message for BasicReplyHeader {}

// Cyclone mode header
//
// This is reverse-engineered from
// https://github.com/ros2/rmw_cyclonedds/blob/master/rmw_cyclonedds_cpp/src/rmw_node.cpp
// https://github.com/ros2/rmw_cyclonedds/blob/master/rmw_cyclonedds_cpp/src/serdata.hpp
// This is a header that Cyclone puts in DDS messages. Same header is used for
// Request and Response.
//
// rmw_cyclonedds_cpp (serdata.hpp) declares it `struct { uint64_t guid; int64_t
// seq; }`, written right after the encapsulation header in the payload's byte
// order: `guid` is the client's request writer's instance handle (opaque, local
// to the client's process) and `seq` its request counter. A server must echo
// both unchanged; a client keeps only the replies whose `guid` is its own.
#[derive(Serialize, Deserialize)]
pub struct CycloneHeader {
  guid: u64,
  seq: i64,
}
impl CycloneHeader {
  // The header's guid lives in bytes 8..16 of `RmwRequestId.writer_gid`, as the
  // little-endian bytes of the number (see `cyclone_unwrap`).
  fn new(r_id: RmwRequestId) -> Self {
    let mut guid = [0; 8];
    guid.copy_from_slice(&r_id.writer_gid.to_bytes16()[8..16]);
    CycloneHeader {
      guid: u64::from_le_bytes(guid),
      seq: r_id.sequence_number,
    }
  }
}
impl Message for CycloneHeader {}

// helper function, because Cyclone Request and Response unwrapping/decoding are
// the same.
//
// The `RmwRequestId.writer_guid` we must reconstruct is the *client's* GUID
// (the request writer), used to correlate a response with its request. Cyclone
// splits this 16-byte GUID across two places:
//   * the lower 8 bytes travel in the CycloneHeader (`guid_second_half`), and
//   * the upper 8 bytes come from `guid_upper_half_source`, which is:
//       - on the server (decoding a request): the DDS writer GUID of the
//         incoming request (the client's request-writer), and
//       - on the client (decoding a response): the client's own GUID, from
//         local client state.
// See https://github.com/ros2/rmw_cyclonedds/blob/master/rmw_cyclonedds_cpp/src/rmw_node.cpp
fn cyclone_unwrap<R: Message>(
  serialized_message: Bytes,
  guid_upper_half_source: GUID,
  encoding: RepresentationIdentifier,
) -> ReadResult<(RmwRequestId, R)> {
  // 1. decode "CycloneHeader" and
  // 2. decode Request/response
  let mut bytes = serialized_message; // ref copy only, to make "mutable"
  let (header, header_size) = deserialize_from_cdr_with_rep_id::<CycloneHeader>(&bytes, encoding)?;
  if bytes.len() < header_size {
    read_error_deserialization!("Service message too short")
  } else {
    // `split_off` leaves `bytes` = [0, header_size) (the header) and returns
    // the payload that follows it. The message is decoded from that
    // payload. The CycloneHeader is 16 bytes (8-aligned), so CDR alignment
    // of the payload is preserved when it is decoded from the start of this
    // slice.
    let payload = bytes.split_off(header_size);
    let (response, _response_bytes) = deserialize_from_cdr_with_rep_id::<R>(&payload, encoding)?;

    // Reassemble the full client GUID: upper 8 bytes from the supplied source,
    // lower 8 bytes from the Cyclone header's guid (as a number, so that a
    // big-endian peer's guid is echoed as the same number).
    let mut client_guid_bytes = [0u8; 16];
    client_guid_bytes[0..8].copy_from_slice(&guid_upper_half_source.to_bytes()[0..8]);
    client_guid_bytes[8..16].copy_from_slice(&header.guid.to_le_bytes());

    let req_id = RmwRequestId {
      writer_gid: crate::gid::Gid::from(GUID::from_bytes(client_guid_bytes)),
      sequence_number: header.seq,
    };
    Ok((req_id, response))
  }
}

pub(super) type SimpleDataReaderR<RW> =
  no_key::SimpleDataReader<RW, ServiceDeserializerAdapter<RW>>;
pub(super) type DataWriterR<RW> = no_key::DataWriter<RW, ServiceSerializerAdapter<RW>>;

pub(super) struct ServiceDeserializerAdapter<RW> {
  phantom: PhantomData<RW>,
}
pub(super) struct ServiceSerializerAdapter<RW> {
  phantom: PhantomData<RW>,
}

impl<RW> ServiceDeserializerAdapter<RW> {
  const REPR_IDS: [RepresentationIdentifier; 2] = [
    RepresentationIdentifier::CDR_BE,
    RepresentationIdentifier::CDR_LE,
  ];
}

impl<RW: Wrapper> no_key::DeserializerAdapter<RW> for ServiceDeserializerAdapter<RW> {
  type Error = ReadError;
  type Decoded = RW;

  fn supported_encodings() -> &'static [RepresentationIdentifier] {
    &Self::REPR_IDS
  }

  fn transform_decoded(decoded: Self::Decoded) -> RW {
    decoded
  }
}

impl<RW: Wrapper> no_key::DefaultDecoder<RW> for ServiceDeserializerAdapter<RW> {
  type Decoder = WrapperDecoder;
  const DECODER: Self::Decoder = WrapperDecoder;
}

#[derive(Clone)]
pub struct WrapperDecoder;

impl<'de, RW> no_key::Decode<'de, RW> for WrapperDecoder
where
  RW: Wrapper,
{
  type Error = ReadError;

  fn decode_bytes(
    self,
    input_bytes: &'de [u8],
    encoding: RepresentationIdentifier,
  ) -> Result<RW, Self::Error> {
    Ok(RW::from_bytes_and_ri(input_bytes, encoding))
  }
}

impl<RW: Wrapper> no_key::SerializerAdapter<RW> for ServiceSerializerAdapter<RW> {
  type Error = WriteError<()>;
  fn output_encoding() -> RepresentationIdentifier {
    RepresentationIdentifier::CDR_LE
  }

  fn to_bytes(value: &RW) -> WriteResult<Bytes, ()> {
    Ok(value.bytes())
  }
}

#[cfg(test)]
mod tests {
  use super::*;
  use crate::gid::Gid;
  use crate::service::VENDOR_ID_ECLIPSE_CYCLONE;

  #[derive(Serialize, Deserialize, Debug, PartialEq)]
  struct Names {
    names: Vec<String>,
  }
  impl Message for Names {}

  // A GID whose prefix starts with `vendor`.
  fn gid(vendor: [u8; 2], rest: u8) -> Gid {
    let mut b = [rest; 16];
    b[0..2].copy_from_slice(&vendor);
    Gid::from(b)
  }

  // The body (after the 4-byte encapsulation) of an rmw_cyclonedds
  // GetParameters-like request `names = ["v_max"]`, little-endian: the header
  // {guid: u64, seq: i64} then the message, as rmw_cyclonedds_cpp's
  // Serialization.cpp writes it.
  fn cyclone_le_body() -> Vec<u8> {
    let mut b = vec![];
    b.extend_from_slice(&0x1122_3344_5566_7788_u64.to_le_bytes()); // guid
    b.extend_from_slice(&1_i64.to_le_bytes()); // seq
    b.extend_from_slice(&1_u32.to_le_bytes()); // names.length
    b.extend_from_slice(&6_u32.to_le_bytes()); // "v_max" + NUL
    b.extend_from_slice(b"v_max\0");
    b
  }

  /// The log records of this module, with their levels (other tests of the
  /// binary, some running DDS, log through it too: their records are not kept).
  struct Capture(std::sync::Mutex<Vec<(log::Level, String)>>);

  impl log::Log for Capture {
    fn enabled(&self, metadata: &log::Metadata) -> bool {
      metadata.target().starts_with(module_path!().trim_end_matches("::tests"))
    }
    fn log(&self, record: &log::Record) {
      if !self.enabled(record.metadata()) {
        return;
      }
      let mut records = self.0.lock().unwrap_or_else(|e| e.into_inner());
      records.push((record.level(), record.args().to_string()));
    }
    fn flush(&self) {}
  }

  static CAPTURE: Capture = Capture(std::sync::Mutex::new(Vec::new()));

  #[test]
  fn a_request_without_related_sample_identity_is_no_warning() {
    // No other test of this binary sets a logger.
    log::set_logger(&CAPTURE).unwrap();
    log::set_max_level(log::LevelFilter::Debug);
    // A RustDDS client's request: Enhanced, its identity only in the DATA.
    let writer = gid([0x01, 0x12], 0x21);
    let mi = MessageInfo::new(None, None, 17, writer, None);
    let body = 0_u32.to_le_bytes(); // no names
    let w = RequestWrapper::<Names>::from_bytes_and_ri(&body, RepresentationIdentifier::CDR_LE);
    let (id, req) = w.unwrap(ServiceMapping::Enhanced, &mi).unwrap();
    assert!(req.names.is_empty());
    assert_eq!(
      id,
      RmwRequestId {
        writer_gid: writer,
        sequence_number: 17
      }
    );
    let records = CAPTURE.0.lock().unwrap_or_else(|e| e.into_inner());
    let about: Vec<_> = records
      .iter()
      .filter(|(_, text)| text.contains("related_sample_identity missing"))
      .collect();
    assert!(!about.is_empty(), "the fallback is logged");
    assert!(
      about.iter().all(|(level, _)| *level > log::Level::Info),
      "logged above debug: {about:?}"
    );
  }

  // A request or reply of the Enhanced mapping is the message's CDR alone, after
  // the encapsulation header; the Basic one puts its header before it.
  #[test]
  fn an_enhanced_or_basic_payload_is_the_message_s_cdr() {
    let names = || Names {
      names: vec!["v_max".into(), "a".into()],
    };
    fn cdr<T: Serialize>(value: &T) -> Vec<u8> {
      let mut bytes = Vec::new();
      rustdds::serialization::to_writer_with_rep_id(
        &mut bytes,
        value,
        RepresentationIdentifier::CDR_LE,
      )
      .unwrap();
      bytes
    }
    let message = cdr(&names());
    // names: 2 strings, "v_max" + NUL, 2 bytes to align the next length, "a" + NUL.
    let mut literal = vec![2, 0, 0, 0, 6, 0, 0, 0];
    literal.extend_from_slice(b"v_max\0\0\0");
    literal.extend_from_slice(&[2, 0, 0, 0, b'a', 0]);
    assert_eq!(message, literal);
    let id = RmwRequestId {
      writer_gid: gid([0x01, 0x0f], 0x21),
      sequence_number: 9,
    };
    let le = RepresentationIdentifier::CDR_LE;
    let enhanced =
      ResponseWrapper::<Names>::new(ServiceMapping::Enhanced, id, le, names()).unwrap();
    assert_eq!(enhanced.bytes()[..], message[..]);
    let request = RequestWrapper::<Names>::new(ServiceMapping::Enhanced, id, le, names()).unwrap();
    assert_eq!(request.bytes()[..], message[..]);
    let basic = ResponseWrapper::<Names>::new(ServiceMapping::Basic, id, le, names()).unwrap();
    let header = cdr(&BasicReplyHeader::new(id.into()));
    assert_eq!(basic.bytes()[..header.len()], header[..]);
    assert_eq!(basic.bytes()[header.len()..], message[..]);
  }

  #[test]
  fn auto_decodes_a_cyclone_request_and_echoes_its_header() {
    let body = cyclone_le_body();
    let writer = gid(VENDOR_ID_ECLIPSE_CYCLONE, 0xab);
    let mi = MessageInfo::new(None, None, 3, writer, None);
    let w = RequestWrapper::<Names>::from_bytes_and_ri(&body, RepresentationIdentifier::CDR_LE);
    let (id, req) = w.unwrap(ServiceMapping::Auto, &mi).unwrap();
    assert_eq!(req.names, vec!["v_max".to_string()]);
    assert_eq!(id.sequence_number, 1);
    assert_eq!(id.writer_gid.as_bytes()[0..8], writer.as_bytes()[0..8]);
    assert_eq!(id.writer_gid.as_bytes()[8..16], body[0..8]);
    // The reply starts with the same 16 bytes, then the response.
    let reply = ResponseWrapper::<Names>::new(
      ServiceMapping::Auto,
      id,
      RepresentationIdentifier::CDR_LE,
      Names { names: vec!["ok".into()] },
    )
    .unwrap()
    .bytes();
    assert_eq!(reply[0..16], body[0..16]);
    assert_eq!(reply[16..20], 1_u32.to_le_bytes());
  }

  #[test]
  fn a_big_endian_cyclone_request_keeps_its_guid_and_seq_as_numbers() {
    let mut b = vec![];
    b.extend_from_slice(&0x1122_3344_5566_7788_u64.to_be_bytes());
    b.extend_from_slice(&5_i64.to_be_bytes());
    b.extend_from_slice(&0_u32.to_be_bytes()); // no names
    let mi = MessageInfo::new(None, None, 1, gid(VENDOR_ID_ECLIPSE_CYCLONE, 1), None);
    let w = RequestWrapper::<Names>::from_bytes_and_ri(&b, RepresentationIdentifier::CDR_BE);
    let (id, req) = w.unwrap(ServiceMapping::Cyclone, &mi).unwrap();
    assert!(req.names.is_empty());
    assert_eq!(id.sequence_number, 5);
    // Replied little-endian: the same numbers in the reply's byte order.
    let reply = ResponseWrapper::<Names>::new(
      ServiceMapping::Cyclone,
      id,
      RepresentationIdentifier::CDR_LE,
      Names { names: vec![] },
    )
    .unwrap()
    .bytes();
    assert_eq!(reply[0..8], 0x1122_3344_5566_7788_u64.to_le_bytes());
    assert_eq!(reply[8..16], 5_i64.to_le_bytes());
  }

  #[test]
  fn auto_decodes_a_fast_dds_request_by_its_related_sample_identity() {
    // Fast DDS: no header; the client's reply reader in the inline QoS.
    let mut body = vec![];
    body.extend_from_slice(&1_u32.to_le_bytes());
    body.extend_from_slice(&6_u32.to_le_bytes());
    body.extend_from_slice(b"v_max\0");
    let related = RmwRequestId {
      writer_gid: gid([0x01, 0x0f], 0x42),
      sequence_number: 7,
    };
    let mi = MessageInfo::new(None, None, 7, gid([0x01, 0x0f], 0x41), Some(related));
    let w = RequestWrapper::<Names>::from_bytes_and_ri(&body, RepresentationIdentifier::CDR_LE);
    let (id, req) = w.unwrap(ServiceMapping::Auto, &mi).unwrap();
    assert_eq!(id, related);
    assert_eq!(req.names, vec!["v_max".to_string()]);
    let reply = ResponseWrapper::<Names>::new(
      ServiceMapping::Auto,
      id,
      RepresentationIdentifier::CDR_LE,
      Names { names: vec![] },
    )
    .unwrap()
    .bytes();
    // No header: just the empty sequence's length.
    assert_eq!(reply[..], 0_u32.to_le_bytes());
  }

  #[test]
  fn auto_resolves_by_vendor_and_clients_use_enhanced() {
    let cyclone = gid(VENDOR_ID_ECLIPSE_CYCLONE, 0);
    let fast = gid([0x01, 0x0f], 0);
    let rust = gid([0x01, 0x12], 0);
    assert_eq!(ServiceMapping::Auto.of_writer(&cyclone), ServiceMapping::Cyclone);
    assert_eq!(ServiceMapping::Auto.of_writer(&fast), ServiceMapping::Enhanced);
    assert_eq!(ServiceMapping::Auto.of_writer(&rust), ServiceMapping::Enhanced);
    let id = RmwRequestId {
      writer_gid: cyclone,
      sequence_number: 1,
    };
    assert_eq!(ServiceMapping::Auto.of_reply(&id), ServiceMapping::Cyclone);
    // Fixed mappings stay what they are.
    assert_eq!(ServiceMapping::Enhanced.of_writer(&cyclone), ServiceMapping::Enhanced);
    assert_eq!(ServiceMapping::Cyclone.of_writer(&fast), ServiceMapping::Cyclone);
    // A client: Cyclone only when every matched server is Cyclone DDS's.
    let reader = |g: Gid| GUID::from(g);
    let (c, f) = (reader(cyclone), reader(fast));
    assert_eq!(ServiceMapping::Auto.for_servers([&c]), ServiceMapping::Cyclone);
    assert_eq!(ServiceMapping::Auto.for_servers([&c, &f]), ServiceMapping::Enhanced);
    assert_eq!(ServiceMapping::Auto.for_servers(std::iter::empty()), ServiceMapping::Enhanced);
    assert_eq!(ServiceMapping::Basic.for_servers([&c]), ServiceMapping::Basic);
  }

  #[test]
  fn an_auto_client_reads_each_reply_in_its_writers_layout() {
    let client = GUID::from(gid([0x01, 0x12], 0x33));
    // From Cyclone DDS: the header echoing our request (guid = our GUID's lower
    // 8 bytes, seq 9), then the response.
    let mut lower = [0; 8];
    lower.copy_from_slice(&Gid::from(client).as_bytes()[8..16]);
    let mut body = vec![];
    body.extend_from_slice(&u64::from_le_bytes(lower).to_le_bytes());
    body.extend_from_slice(&9_i64.to_le_bytes());
    body.extend_from_slice(&0_u32.to_le_bytes());
    let mi = MessageInfo::new(None, None, 1, gid(VENDOR_ID_ECLIPSE_CYCLONE, 5), None);
    let w = ResponseWrapper::<Names>::from_bytes_and_ri(&body, RepresentationIdentifier::CDR_LE);
    let (id, resp) = w.unwrap(ServiceMapping::Auto, mi, client).unwrap();
    assert_eq!(id, RmwRequestId { writer_gid: Gid::from(client), sequence_number: 9 });
    assert!(resp.names.is_empty());
    // From Fast DDS: no header, the id in the related sample identity.
    let related = RmwRequestId { writer_gid: Gid::from(client), sequence_number: 4 };
    let mi = MessageInfo::new(None, None, 1, gid([0x01, 0x0f], 5), Some(related));
    let w = ResponseWrapper::<Names>::from_bytes_and_ri(&0_u32.to_le_bytes(), RepresentationIdentifier::CDR_LE);
    let (id, _) = w.unwrap(ServiceMapping::Auto, mi, client).unwrap();
    assert_eq!(id, related);
  }
}
