#!/usr/bin/env python3
"""Development-time cross-check of a hinfix trace with the Python `mcap` package (pip install mcap).

Not used by the tests or the product. Prints the channels, their encodings and schemas, the message
count per topic, and the final-result message of a trace written by `campaign run`:

    python3 scripts/check_trace.py results/smoke/traces/<job>.mcap
"""
import json
import sys
from collections import Counter

from mcap.reader import make_reader


def main(path: str) -> None:
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        for ch in summary.channels.values():
            sch = summary.schemas[ch.schema_id]
            print(f"channel {ch.topic}: messages {ch.message_encoding}, schema {sch.name} ({sch.encoding})")
        counts = Counter()
        result = None
        for _schema, channel, message in reader.iter_messages():
            counts[channel.topic] += 1
            doc = json.loads(message.data)
            if channel.topic.endswith("/result"):
                result = doc
        for topic, n in counts.items():
            print(f"{topic}: {n} messages")
        if result is not None:
            print(f"result: status {result['status']['kind']}, gamma {result['gamma']}, iterations {result['iterations']}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: check_trace.py TRACE.mcap")
    main(sys.argv[1])
