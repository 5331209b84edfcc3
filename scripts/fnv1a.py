#!/usr/bin/env python3
"""64-bit FNV-1a of a file's bytes, as 16 hex digits: the reference for the model fingerprint's test.

The fingerprint of a model (src/model/fingerprint.rs) is FNV-1a of its serialised description; the test
compares the description of a fixed small model with tests/data/fingerprint/cantilever_description.json and its
fingerprint with the value this script prints for that file — an implementation of FNV-1a written apart from
the crate's (Fowler, Noll, Vo; offset basis and prime from IETF draft-eastlake-fnv-17, §2).

    python3 scripts/fnv1a.py tests/data/fingerprint/cantilever_description.json
"""

import sys

OFFSET = 0xCBF29CE484222325
PRIME = 0x100000001B3


def fnv1a(data: bytes) -> int:
    h = OFFSET
    for b in data:
        h ^= b
        h = (h * PRIME) % (1 << 64)
    return h


def main() -> int:
    for path in sys.argv[1:]:
        with open(path, "rb") as f:
            print(f"{fnv1a(f.read()):016x}  {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
