"""reads an MCAP file with the official `mcap` Python reader and prints what it read as JSON.

used by tests/ros/mcap_writer_test.cc, which compares the JSON with what it wrote. the file is
read three ways:
  - SeekingReader (the summary: Statistics, Schema, Channel, ChunkIndex and MetadataIndex
    records found through the Footer and the SummaryOffset records), with the messages read
    through the chunk indexes and message indexes in log-time order;
  - NonSeekingReader with validate_crcs=True (every record in file order; the data section CRC
    of DataEnd and each Chunk's CRC checked);
  - rosbags' own MCAP storage reader (another implementation) when the profile is "ros2"
    is not needed here: it needs a rosbag2 folder (tests/ros/rosbag2_export_test.py).
the Footer's summary CRC, which neither reader checks, is recomputed here with zlib.

usage: mcap_read_check.py FILE.mcap
"""
import json
import struct
import sys
import zlib

from mcap.reader import SeekingReader
from mcap.records import Chunk, DataEnd, Footer, MessageIndex
from mcap.stream_reader import StreamReader, get_chunk_data_stream

path = sys.argv[1]
out = {}
with open(path, "rb") as f:
    raw = f.read()

with open(path, "rb") as f:
    reader = SeekingReader(f, validate_crcs=True)
    header = reader.get_header()
    out["profile"] = header.profile
    out["library"] = header.library
    summary = reader.get_summary()
    st = summary.statistics
    out["statistics"] = {
        "message_count": st.message_count,
        "schema_count": st.schema_count,
        "channel_count": st.channel_count,
        "chunk_count": st.chunk_count,
        "metadata_count": st.metadata_count,
        "message_start_time": st.message_start_time,
        "message_end_time": st.message_end_time,
        "channel_message_counts": {str(k): v for k, v in st.channel_message_counts.items()},
    }
    out["schemas"] = {
        str(s.id): {"name": s.name, "encoding": s.encoding, "data": s.data.decode("latin-1")}
        for s in summary.schemas.values()
    }
    out["channels"] = {
        str(c.id): {
            "schema_id": c.schema_id,
            "topic": c.topic,
            "message_encoding": c.message_encoding,
            "metadata": dict(c.metadata),
        }
        for c in summary.channels.values()
    }
    out["chunk_indexes"] = [
        {
            "compression": c.compression,
            "message_start_time": c.message_start_time,
            "message_end_time": c.message_end_time,
            "channels": sorted(c.message_index_offsets),
        }
        for c in summary.chunk_indexes
    ]
    out["metadata"] = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    out["messages"] = [
        {
            "channel": c.id,
            "sequence": m.sequence,
            "log_time": m.log_time,
            "publish_time": m.publish_time,
            "data": m.data.hex(),
        }
        for _, c, m in reader.iter_messages(log_time_order=True)
    ]

# every record in file order, with the CRCs checked; the message indexes point at the messages
with open(path, "rb") as f:
    records = list(StreamReader(f, emit_chunks=True, validate_crcs=True).records)
# the record kinds in file order, runs of one kind written once
order = []
for r in records:
    if not order or order[-1] != type(r).__name__:
        order.append(type(r).__name__)
out["record_order"] = order
data_end = next(r for r in records if isinstance(r, DataEnd))
out["data_section_crc_set"] = data_end.data_section_crc != 0
footer = next(r for r in records if isinstance(r, Footer))
# the summary CRC: from the summary's start through the footer's summary_offset_start field
end = len(raw) - 8 - 4  # the magic, the crc
out["summary_crc_ok"] = footer.summary_crc == zlib.crc32(raw[footer.summary_start:end])
(footer_length,) = struct.unpack_from("<Q", raw, end - 16 - 8)
out["footer_length"] = footer_length
# each message index entry names the offset of a message record in its chunk's records
index_ok = True
chunk = b""
for r in records:
    if isinstance(r, Chunk):
        stream, length = get_chunk_data_stream(r, validate_crc=True)
        chunk = stream.read(length)
    elif isinstance(r, MessageIndex):
        for log_time, offset in r.records:
            op = chunk[offset]
            (channel,) = struct.unpack_from("<H", chunk, offset + 9)
            (t,) = struct.unpack_from("<Q", chunk, offset + 9 + 2 + 4)
            index_ok &= op == 0x05 and channel == r.channel_id and t == log_time
out["message_indexes_ok"] = index_ok
json.dump(out, sys.stdout)
