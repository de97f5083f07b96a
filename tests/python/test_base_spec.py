# SPDX-License-Identifier: MIT
"""A second decoder of container 1.3's BASE chunk, written from spec/container.md (4.8, 4.9)
alone, against the library's: parameters bit for bit and every marginal mass equal."""
import math
import struct

import cbrdf
from conftest import run_cli


class RangeDecoder:
    """Spec 4.9: LZMA's binary decoder, 11-bit probabilities, zeros past the end."""

    def __init__(self, data):
        self.data, self.pos, self.past = data, 0, 0
        self.range, self.code = 0xFFFFFFFF, 0
        for _ in range(4):
            self.code = ((self.code << 8) | self.next()) & 0xFFFFFFFF

    def next(self):
        if self.pos < len(self.data):
            self.pos += 1
            return self.data[self.pos - 1]
        self.past += 1
        return 0

    def bit(self, ctx, key):
        p = ctx.setdefault(key, 1024)
        bound = (self.range >> 11) * p
        if self.code < bound:
            self.range, b = bound, 0
            ctx[key] = p + ((2048 - p) >> 4)
        else:
            self.code -= bound
            self.range -= bound
            ctx[key], b = p - (p >> 4), 1
        while self.range < (1 << 24):
            self.range = (self.range << 8) & 0xFFFFFFFF
            self.code = ((self.code << 8) | self.next()) & 0xFFFFFFFF
        return b

    def uint(self, ctx, name):
        n = 0
        while self.bit(ctx, (name, "exp", n)):
            n += 1
            assert n <= 23
        x = 1
        for j in range(n - 1, -1, -1):
            x = 2 * x + self.bit(ctx, (name, "mant", n, j))
        return x - 1

    def sint(self, ctx, name):
        if not self.bit(ctx, (name, "zero")):
            return 0
        s = self.bit(ctx, (name, "sign"))
        m = self.uint(ctx, name) + 1
        return -m if s else m


def chunks(data):
    assert data[:8] == b"\x8bCBR\r\n\x1a\n"
    major, minor = struct.unpack_from("<HH", data, 8)
    pos, out = 12, {}
    while pos < len(data):
        tag = data[pos:pos + 4].decode()
        stored, flags, plen = struct.unpack_from("<III", data, pos + 4)
        assert flags == 0  # the reference writer stores HEAD and BASE without zstd
        out[tag] = data[pos + 16:pos + 16 + stored]
        pos += 16 + stored + 8
    return minor, out


def masses(codes, hi_units, span_units, bits):
    """Spec 4.3's reconstruction with the 1.3 range."""
    top = (1 << bits) - 1
    if not any(codes):
        return [0.0] * len(codes)
    hi = struct.unpack("<f", struct.pack("<f", -hi_units / 32.0))[0]
    lo = struct.unpack("<f", struct.pack("<f", -(hi_units + span_units) / 32.0))[0]
    span = hi - lo
    w = [math.exp(((q - top) * span) / (top - 1)) if q else 0.0 for q in codes]
    total = 0.0
    for v in w:
        total += v
    return [v / total for v in w]


def decode_base(payload, slice_count):
    bits, flags = payload[0], payload[1]
    ends = list(payload[2:2 + slice_count])
    pos = 2 + slice_count
    counts = [[0] * 3 for _ in range(slice_count)]
    if flags & 1:
        for s in range(slice_count):
            for c in range(3):
                counts[s][c] = payload[pos]
                pos += 1
    comps = []
    for s in range(slice_count):
        for c in range(3):
            for k in range(1 + counts[s][c]):
                fam, theta, scale = struct.unpack_from("<Bff", payload, pos)
                pos += 9
                comps.append((s, c, k, fam, theta, scale))
    dec, ctx = RangeDecoder(payload[pos:]), {}
    top = (1 << bits) - 1
    prev = {}  # axis -> (codes, H, D)
    tables = []
    for s, c, k, *_ in comps:
        width = ends[s] - (ends[s - 1] if s else 0)
        for a, n in enumerate((90, width, 180)):
            ph, pd = (prev[a][1], prev[a][2]) if a in prev else (0, 0)
            h = ph + dec.sint(ctx, ("hi", a))
            d = pd + dec.sint(ctx, ("span", a))
            p1 = dec.bit(ctx, ("pred", a, 0))
            mode = 2 * p1 + dec.bit(ctx, ("pred", a, 1 + p1))
            ref = prev[a][0] if a in prev else None
            first = ref[0] if ref else top
            same = ref is not None and len(ref) == n
            assert mode < 2 or same
            q, cls = [], 2
            for i in range(n):
                if i == 0:
                    pred = first
                elif mode == 1 and i >= 2:
                    pred = 2 * q[i - 1] - q[i - 2]
                elif mode == 2:
                    pred = q[i - 1] + ref[i] - ref[i - 1]
                elif mode == 3 and d > 0:
                    pred = q[i - 1] + (2 * (ref[i] - ref[i - 1]) * prev[a][2] + d) // (2 * d)
                else:
                    pred = q[i - 1]
                e = dec.sint(ctx, ("res", a, cls))
                q.append(min(max(pred, 0), top) + e)
                assert 0 <= q[-1] <= top
                cls = 0 if e == 0 else 1 if abs(e) <= 2 else 2
            tables.append(masses(q, h, d, bits))
            prev[a] = (q, h, d)
    assert dec.pos == len(dec.data) and dec.past <= 4
    return bits, comps, tables


def test_spec_decoder_reads_what_the_library_reads(tmp_path):
    binary = tmp_path / "plastic.binary"
    run_cli("sample", "plastic", "-o", binary)
    for extra in ([], ["--components", "2", "--slices", "3"], ["--bits", "14"]):
        out = tmp_path / "p.cbrdf"
        run_cli("encode", binary, "-o", out, "--format-version", "1.3", "--no-metrics", *extra)
        data = out.read_bytes()
        minor, ch = chunks(data)
        assert minor == 3 and "BASE" in ch and "MARG" not in ch
        assert ch["HEAD"][0] == 0
        bits, comps, tables = decode_base(ch["BASE"], ch["HEAD"][1])
        model = cbrdf.decode(data)
        assert model.bits == bits
        t = 0
        for s, c, k, fam, theta, scale in comps:
            comp = model.slices[s].channels[c].components[k]
            assert comp.theta == theta and comp.scale == scale
            for axis in (comp.pdf_h, comp.pdf_d, comp.pdf_p):
                assert list(axis) == tables[t]
                t += 1
