# SPDX-License-Identifier: MIT
"""A second decoder of container 1.3's BASE chunk and RESD's range-coded codes, written from
spec/container.md (4.4, 4.6, 4.8, 4.9) alone, against the library's: parameters bit for bit,
every marginal mass equal, and the residual codes the C++ decoder reads."""
import math
import struct
import subprocess
from pathlib import Path

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


# ---- RESD's range-coded codes (spec 4.6, "Range-coded codes"; 4.4 for the mask) ---------------

# FNV-1a (64-bit) over the decoded codes as little-endian int32, channel-major MERL order: the
# value tests/base_coding_test.cc pins for the C++ decoder of the same golden file.
RANGED_GOLDEN = "v1.3-ranged-residual-frank6-b10.cbrdf"
RANGED_CODES_FNV = 0x74BA0D728C343ABD


def below_horizon():
    """Spec 4.4's G for one channel, in MERL index order."""
    g = bytearray(90 * 90 * 180)
    i = 0
    for h in range(90):
        th = h / 90.0 * h / 90.0 * (math.pi / 2)
        sth, cth = math.sin(th), math.cos(th)
        for d in range(90):
            td = d / 90.0 * (math.pi / 2)
            std, ctd = math.sin(td), math.cos(td)
            for p in range(180):
                pd = p / 180.0 * math.pi
                dx = std * math.cos(pd)
                dz = ctd
                wi_z = -dx * sth + dz * cth
                c = (dx * cth + dz * sth) * sth + wi_z * cth
                wo_z = 2 * c * cth - wi_z
                g[i] = 1 if (wi_z <= 0 or wo_z <= 0) else 0
                i += 1
    return g


def decode_ranged_codes(stream, masked):
    """The codes of every measured bin, exactly as the spec's pseudo-code says."""
    n_bins = 90 * 90 * 180
    q = [0] * (3 * n_bins)
    data, pos, past = stream, 0, 0
    rng, code = 0xFFFFFFFF, 0

    def nxt():
        nonlocal pos, past
        if pos < len(data):
            pos += 1
            return data[pos - 1]
        past += 1
        return 0

    for _ in range(4):
        code = ((code << 8) | nxt()) & 0xFFFFFFFF
    probs = {}

    def bit(key):
        nonlocal rng, code
        p = probs.get(key, 16384)
        bound = (rng >> 15) * p
        if code < bound:
            rng, b = bound, 0
            probs[key] = p + ((32768 - p) >> 4)
        else:
            code -= bound
            rng -= bound
            probs[key], b = p - (p >> 4), 1
        while rng < (1 << 24):
            rng = (rng << 8) & 0xFFFFFFFF
            code = ((code << 8) | nxt()) & 0xFFFFFFFF
        return b

    def tz3(v):
        n = 0
        while n < 3 and v % 2 == 0:
            v //= 2
            n += 1
        return n

    def sg(v):
        return 0 if v == 0 else 1 if v > 0 else 2

    cls_of = {}
    for d in range(8):
        for p in range(8):
            lv = min(tz3(d), tz3(p))
            cls_of[d, p] = 0 if lv == 3 else 1 + 2 * (2 - lv) + (0 if d % (2 ** (lv + 1)) == 0 else 1)
    tops = (0, 1, 2, 4, 6, 9, 14, 22, 40, 80)
    slab = 90 * 180
    for c in range(3):
        base = c * n_bins
        for h in range(90):
            for d in range(90):
                for p in range(180):
                    i = (h * 90 + d) * 180 + p
                    if masked[base + i]:
                        continue
                    a = q[base + i - slab] if h > 0 else 0
                    s = 0
                    if h > 0:
                        row = base + i - p - slab
                        s = 2 * abs(a) + abs(q[row + (p + 179) % 180]) + abs(q[row + (p + 1) % 180])
                    b = q[base + i - n_bins] if c > 0 else 0
                    s += 2 * abs(b)
                    bucket = sum(1 for t in tops if s > t)
                    k = 2 * (11 * cls_of[d % 8, p % 8] + bucket) + (1 if c > 0 else 0)
                    if not bit(("zero", k)):
                        continue
                    e = q[base + i - 2 * slab] if h > 1 else 0
                    neg = bit(("sign", 9 * sg(a) + 3 * sg(b) + sg(e)))
                    n = 0
                    while bit(("exp", k, n)):
                        n += 1
                        assert n <= 28
                    x = 1
                    for j in range(n - 1, -1, -1):
                        x = 2 * x + bit(("mant", k, n, j))
                    assert x <= 1 << 28
                    q[base + i] = -x if neg else x
    assert pos == len(data) and past <= 4
    return q


def test_spec_decoder_reads_range_coded_residual_codes():
    path = Path(__file__).resolve().parents[1] / "data" / "golden" / RANGED_GOLDEN
    data = path.read_bytes()
    _, minor = struct.unpack_from("<HH", data, 8)
    assert minor == 3
    pos, ch = 12, {}
    while pos < len(data):
        tag = data[pos:pos + 4].decode()
        stored, flags, plen = struct.unpack_from("<III", data, pos + 4)
        raw = data[pos + 16:pos + 16 + stored]
        if flags & 1:  # one zstd frame (spec 2)
            raw = subprocess.run(["zstd", "-d", "-c"], input=raw, capture_output=True,
                                 check=True).stdout
        assert len(raw) == plen
        ch[tag] = raw
        pos += 16 + stored + 8
    # MASK: against the below-horizon mask, one clear run (the standard mask).
    mask = ch["MASK"]
    assert mask[0] == 1 and mask[1] == 1
    count = struct.unpack_from("<I", mask, 4)[0]
    assert struct.unpack_from("<I", mask, 16)[0] == 1
    masked = below_horizon() * 3
    assert sum(masked) == count
    resd = ch["RESD"]
    mode, predictor = resd[0], resd[1]
    assert mode == 3 and predictor == 2
    escapes = struct.unpack_from("<I", resd, 28)[0]
    at = 32 + 8100 + 2
    length = struct.unpack_from("<I", resd, at)[0]
    stream = resd[at + 4:at + 4 + length]
    q = decode_ranged_codes(stream, masked)
    # The escapes end the payload: varint gap, f64 each.
    rest = resd[at + 4 + length:]
    k = 0
    for _ in range(escapes):
        while rest[k] & 0x80:
            k += 1
        k += 1 + 8
    assert k == len(rest)
    h = 0xCBF29CE484222325
    for v in q:
        for byte in struct.pack("<i", v):
            h = ((h ^ byte) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    assert any(q) and h == RANGED_CODES_FNV, hex(h)
