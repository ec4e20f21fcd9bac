# SPDX-License-Identifier: Apache-2.0
"""Containers written directly from formats/SPEC.md by a second, independent writer (if these
files validate, the spec is complete), including hostile ones: any codec, any declared raw size,
and zstd frames built by hand from RLE blocks (RFC 8878) that record any content size. XXH3-64
comes from the system libxxhash through ctypes."""

import ctypes
import ctypes.util
import json
import struct


def _load_xxhash():
    for name in (ctypes.util.find_library("xxhash"), "libxxhash.so.0", "libxxhash.so"):
        if not name:
            continue
        try:
            lib = ctypes.CDLL(name)
        except OSError:
            continue
        lib.XXH3_64bits.restype = ctypes.c_uint64
        lib.XXH3_64bits.argtypes = [ctypes.c_char_p, ctypes.c_size_t]
        return lib
    raise RuntimeError("libxxhash not found")


_XXH = _load_xxhash()


def xxh3_64(data):
    return _XXH.XXH3_64bits(bytes(data), len(data))


MAGIC = bytes([0xAB, ord("G"), ord("B"), ord("K"), 0x0D, 0x0A, 0x1A, 0x0A])
KIND_TEST = 0x7FFF
SECTION_METADATA, SECTION_IMAGE, SECTION_PRIVATE = 1, 0x100, 0x10000
CODEC_RAW, CODEC_ZSTD = 0, 1


def metadata(tool="pytest", version="1.0", **extra):
    doc = {"schema": "glintbake.container-metadata/1", "asset_kind": "test",
           "generator": {"tool": tool, "version": version}, "parameters": {"n": 1},
           "inputs": [{"name": "input.png", "hash": "xxh3-128:" + "0f" * 16}]}
    doc.update(extra)
    return json.dumps(doc).encode()


def image_payload(width, height, channels, layers, values):
    header = struct.pack("<6IQ", 0x474D4947, width, height, channels, layers, 0, 0)
    assert len(values) == width * height * channels * layers
    return header + struct.pack("<%df" % len(values), *values)


def build_container(sections, kind=KIND_TEST, major=1, minor=0):
    """sections: list of (type, key, raw bytes), stored raw (codec 0), or of (type, key, stored
    bytes, codec, raw_size) for any codec and any declared size.
    Layout per SPEC.md: 128-byte header, 64-aligned sections, 64-byte index entries, header last."""
    body = bytearray()
    entries = []
    offset = 128
    for section in sections:
        stype, key, data = section[:3]
        codec, raw_size = section[3:] if len(section) > 3 else (CODEC_RAW, len(data))
        pad = (-offset) % 64
        body += b"\0" * pad
        offset += pad
        entries.append(struct.pack("<IIQQQQQII8x", stype, codec, key, offset, len(data), raw_size, xxh3_64(data), 0, 0))
        body += data
        offset += len(data)
    pad = (-offset) % 64
    body += b"\0" * pad
    offset += pad
    index = b"".join(entries)
    index_offset = offset
    body += index
    file_size = index_offset + len(index)
    header = bytearray(struct.pack("<8sHHIIIIIQQQQQQ", MAGIC, major, minor, kind, 128, 0, len(sections), 0,
                                   index_offset, len(index), file_size, xxh3_64(body), xxh3_64(index), 0))
    header += b"\0" * (128 - len(header))
    struct.pack_into("<Q", header, 72, xxh3_64(header))
    return bytes(header) + bytes(body)




def zstd_rle_frame(content_size, produced=None, byte=b"\0"):
    """One zstd frame whose header records content_size and whose RLE blocks really produce
    `produced` bytes (default content_size) of `byte`: about 4 bytes per 128 KiB."""
    produced = content_size if produced is None else produced
    return zstd_block_frame(content_size, [("rle", byte, produced)])


def zstd_block_frame(content_size, pieces, window_log=None):
    """One zstd frame built from raw and RLE blocks (RFC 8878): pieces are ("raw", bytes) or
    ("rle", byte, count), cut into blocks of at most 128 KiB. Single segment (the window is the
    content) unless window_log is given."""
    if window_log is None:
        frame = struct.pack("<IBQ", 0xFD2FB528, 0xE0, content_size)  # single segment, 8-byte content size
    else:
        frame = struct.pack("<IBBQ", 0xFD2FB528, 0xC0, (window_log - 10) << 3, content_size)
    blocks = []
    for piece in pieces:
        if piece[0] == "raw":
            data = piece[1]
            blocks += [(0, data[at:at + 128 * 1024]) for at in range(0, len(data), 128 * 1024)] or [(0, b"")]
        else:
            left = piece[2]
            while True:
                n = min(128 * 1024, left)
                blocks.append((1, piece[1], n))
                left -= n
                if left == 0:
                    break
    for i, block in enumerate(blocks):
        last = 1 if i == len(blocks) - 1 else 0
        if block[0] == 0:
            frame += struct.pack("<I", last | (len(block[1]) << 3))[:3] + block[1]
        else:
            frame += struct.pack("<I", last | (1 << 1) | (block[2] << 3))[:3] + block[1]
    return frame


def zstd_with_window(frame, window_log, rle_tail=0):
    """The blocks of a zstd frame (any of this writer's, which set no checksum) under a header
    declaring a window of 2^window_log bytes (not single segment), plus rle_tail zero bytes in RLE
    blocks after them, the content size grown to match: compressed blocks whose window the frame
    header alone decides."""
    fhd = frame[4]
    single = (fhd >> 5) & 1
    assert not (fhd >> 2) & 1, "no frame checksum"
    fcs_size = (single, 2, 4, 8)[fhd >> 6]
    fcs_at = 5 + (0 if single else 1) + (0, 1, 2, 4)[fhd & 3]
    content = int.from_bytes(frame[fcs_at:fcs_at + fcs_size], "little") + (256 if fcs_size == 2 else 0)
    blocks = bytearray(frame[fcs_at + fcs_size:])
    if rle_tail:
        at = 0
        while True:  # find the last block and clear its flag
            header = int.from_bytes(blocks[at:at + 3], "little")
            size = 1 if (header >> 1) & 3 == 1 else header >> 3
            if header & 1:
                blocks[at] &= 0xFE
                break
            at += 3 + size
        blocks += zstd_block_frame(rle_tail, [("rle", b"\0", rle_tail)], window_log=window_log)[14:]
    header = struct.pack("<IBBQ", 0xFD2FB528, 0xC0, (window_log - 10) << 3, content + rle_tail)
    return header + bytes(blocks)


def read_sections(data):
    """The sections of a container's bytes as build_container takes them: (type, key, stored bytes,
    codec, raw_size), in index order, so a test can rebuild a real file with one section changed."""
    index_offset, index_size = struct.unpack_from("<QQ", data, 32)
    sections = []
    for at in range(index_offset, index_offset + index_size, 64):
        stype, codec, key, offset, stored, raw = struct.unpack_from("<IIQQQQ", data, at)
        sections.append((stype, key, data[offset:offset + stored], codec, raw))
    return sections
