"""Reads an MCAP file with the reference Python reader (PyPI `mcap`) and
prints what it found as one JSON object: the header, the schemas, the
channels and every message (topic, times, sequence, decoded payload), for
tests/replay.rs to compare with the trace the file was written from."""

import json
import sys

from mcap.reader import make_reader


def main(path):
    with open(path, "rb") as stream:
        reader = make_reader(stream)
        header = reader.get_header()
        summary = reader.get_summary()
        schemas = {
            str(s.id): {
                "name": s.name,
                "encoding": s.encoding,
                "data": json.loads(s.data.decode("utf-8")),
            }
            for s in summary.schemas.values()
        }
        channels = [
            {
                "id": c.id,
                "topic": c.topic,
                "message_encoding": c.message_encoding,
                "schema": str(c.schema_id),
                "metadata": dict(c.metadata),
            }
            for c in sorted(summary.channels.values(), key=lambda c: c.id)
        ]
        messages = [
            {
                "topic": channel.topic,
                "log_time": message.log_time,
                "publish_time": message.publish_time,
                "sequence": message.sequence,
                "data": json.loads(message.data.decode("utf-8")),
            }
            for _, channel, message in reader.iter_messages(log_time_order=False)
        ]
        counts = {str(k): v for k, v in summary.statistics.channel_message_counts.items()}
    json.dump(
        {
            "profile": header.profile,
            "library": header.library,
            "schemas": schemas,
            "channels": channels,
            "messages": messages,
            "message_count": summary.statistics.message_count,
            "channel_message_counts": counts,
        },
        sys.stdout,
    )


if __name__ == "__main__":
    main(sys.argv[1])
