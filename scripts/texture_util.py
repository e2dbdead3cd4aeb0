"""Deterministic building blocks of the scripts that write the scenes' own textures and meshes:
a fixed hash for noise (no random state, so the files in the repository are exactly what the
scripts write) and an 8-bit PNG writer, standard library only."""
import struct
import zlib


def hash01(*values):
    h = 2166136261
    for v in values:
        h = ((h ^ (v & 0xFFFFFFFF)) * 16777619) & 0xFFFFFFFF
    h ^= h >> 15
    h = (h * 0x2C1B3C6D) & 0xFFFFFFFF
    h ^= h >> 12
    return h / 2**32


def write_png(path, width, height, channels, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    color_type = {1: 0, 3: 2}[channels]

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, color_type, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw, 9)) +
                chunk(b"IEND", b""))
