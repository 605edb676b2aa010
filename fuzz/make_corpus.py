#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz targets into fuzz/corpus/<target>/ (run from anywhere).

    fuzz/make_corpus.py [BUILD_DIR]

Small, valid inputs of every surface: PLY (ascii, binary little/big endian, lists, doubles), PCD
(ascii, binary, binary_compressed with real LZF back references), PlanPickStream message sequences
(varint-delimited, as fuzz_cloud_stream reads them), requests (protoc --encode of text protos, one
selector byte first), the repo's YAML examples and dumps, and HSES / RDT datagrams. BUILD_DIR (a
normal build, default build/) supplies `tubepick params --dump` and `tubepick-server --print-config`;
without it those two seeds are skipped. Needs python3 and protoc (deploy/install-deps.sh).
"""
import os
import shutil
import struct
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")
POINTS = [(0.0, 0.0, 1.0), (0.1, -0.2, 1.05), (-0.3, 0.2, 1.1), (0.25, 0.125, 0.95)]


def write(target, name, data):
    os.makedirs(os.path.join(CORPUS, target), exist_ok=True)
    with open(os.path.join(CORPUS, target, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def packed(points, fmt="<fff"):
    return b"".join(struct.pack(fmt, *p) for p in points)


# --- PLY ------------------------------------------------------------------------------------------
def ply_header(fmt, elements):
    lines = ["ply", "format %s 1.0" % fmt, "comment seed"]
    for name, count, props in elements:
        lines.append("element %s %d" % (name, count))
        lines += ["property " + p for p in props]
    return ("\n".join(lines) + "\nend_header\n").encode()


def ply():
    xyz = ["float x", "float y", "float z"]
    ascii_body = "".join("%g %g %g\n" % p for p in POINTS)
    write("fuzz_ply_reader", "ascii.ply", ply_header("ascii", [("vertex", 4, xyz)]) + ascii_body.encode())
    write("fuzz_ply_reader", "ascii_crlf.ply",
          (ply_header("ascii", [("vertex", 4, xyz)]) + ascii_body.encode()).replace(b"\n", b"\r\n"))
    write("fuzz_ply_reader", "binary_le.ply", ply_header("binary_little_endian", [("vertex", 4, xyz)]) + packed(POINTS))
    props = ["double x", "double y", "double z", "uchar red", "uchar green", "uchar blue"]
    body = b"".join(struct.pack(">dddBBB", *p, 10, 20, 30) for p in POINTS)
    write("fuzz_ply_reader", "binary_be_double_rgb.ply", ply_header("binary_big_endian", [("vertex", 4, props)]) + body)
    # A face element with a list before the vertices, and a list inside the vertex element.
    faces = struct.pack("<BiiiBii", 3, 0, 1, 2, 2, 2, 3)
    write("fuzz_ply_reader", "binary_le_faces_first.ply",
          ply_header("binary_little_endian", [("face", 2, ["list uchar int vertex_indices"]),
                                              ("vertex", 4, xyz)]) + faces + packed(POINTS))
    body = b"".join(struct.pack("<fffHhh", *p, 2, 7, 8) for p in POINTS)
    write("fuzz_ply_reader", "binary_le_vertex_list.ply",
          ply_header("binary_little_endian", [("vertex", 4, xyz + ["list ushort short ids"])]) + body)
    write("fuzz_ply_reader", "ascii_faces.ply",
          ply_header("ascii", [("vertex", 4, xyz), ("face", 1, ["list uchar int vertex_indices"])])
          + ascii_body.encode() + b"3 0 1 2\n")
    write("fuzz_ply_reader", "ascii_nan.ply",
          ply_header("ascii", [("vertex", 2, xyz)]) + b"nan 0 1\n1e999 -inf +2\n")


# --- PCD ------------------------------------------------------------------------------------------
def lzf_compress(data):
    """liblzf format: literal runs (ctrl < 32) and back references (length - 2 in 3 bits, 13-bit offset)."""
    out, literal, i = bytearray(), bytearray(), 0

    def flush():
        nonlocal literal
        while literal:
            run = literal[:32]
            out.append(len(run) - 1)
            out.extend(run)
            literal = literal[32:]

    while i < len(data):
        best_len, best_back = 0, 0
        for start in range(max(0, i - 8192), i):
            n = 0
            while i + n < len(data) and n < 264 and data[start + n] == data[i + n]:
                n += 1
            if n > best_len:
                best_len, best_back = n, i - start
        if best_len >= 3:
            flush()
            length, back = best_len - 2, best_back - 1
            if length < 7:
                out.append((length << 5) | (back >> 8))
            else:
                out += bytes([(7 << 5) | (back >> 8), length - 7])
            out.append(back & 0xFF)
            i += best_len
        else:
            literal.append(data[i])
            i += 1
    flush()
    return bytes(out)


def pcd_header(fields, sizes, types, counts, n, data):
    return ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\n"
            "COUNT %s\nWIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA %s\n"
            % (fields, sizes, types, counts, n, n, data)).encode()


def pcd():
    n = len(POINTS)
    ascii_body = "".join("%g %g %g\n" % p for p in POINTS).encode()
    write("fuzz_pcd_reader", "ascii.pcd", pcd_header("x y z", "4 4 4", "F F F", "1 1 1", n, "ascii") + ascii_body)
    write("fuzz_pcd_reader", "binary.pcd", pcd_header("x y z", "4 4 4", "F F F", "1 1 1", n, "binary") + packed(POINTS))
    body = b"".join(struct.pack("<dddI", *p, 0xFF8040) for p in POINTS)
    write("fuzz_pcd_reader", "binary_double_rgb.pcd",
          pcd_header("x y z rgb", "8 8 8 4", "F F F U", "1 1 1 1", n, "binary") + body)
    # binary_compressed: field-major (all x, then all y, ...), then LZF; a repeated point gives
    # back references.
    points = POINTS + POINTS + [POINTS[0]] * 8
    columns = b"".join(struct.pack("<%df" % len(points), *[p[a] for p in points]) for a in range(3))
    compressed = lzf_compress(columns)
    write("fuzz_pcd_reader", "binary_compressed.pcd",
          pcd_header("x y z", "4 4 4", "F F F", "1 1 1", len(points), "binary_compressed")
          + struct.pack("<II", len(compressed), len(columns)) + compressed)
    normals = pcd_header("x y z normal", "4 4 4 4", "F F F F", "1 1 1 3", 2, "ascii") + b"0 0 1 0 0 1\n1 2 3 0 1 0\n"
    write("fuzz_pcd_reader", "ascii_count3.pcd", normals)


# --- protobuf -------------------------------------------------------------------------------------
def encode(message, text):
    return subprocess.run(["protoc", "-I", os.path.join(ROOT, "proto"), "--encode=tubepick.v1." + message,
                           "tubepick/v1/requests.proto", "tubepick/v1/wrench.proto"],
                          input=text.encode(), stdout=subprocess.PIPE, check=True).stdout


def escaped(data):
    return "".join("\\%03o" % b for b in data)


CELL = """cell {
  bin_inner_size { x: 0.6 y: 0.4 z: 0.25 }
  sensor_pose { position { z: 1.2 } orientation { x: 1 } }
  tube_radius: 0.01 tube_length: 0.4 tube_mass: 0.04
  place_pose { position { x: 0.1 y: 0.7 z: 0.05 } orientation { w: 1 } }
}
"""


def varint(n):
    out = bytearray()
    while True:
        b = n & 0x7F
        n >>= 7
        out.append(b | (0x80 if n else 0))
        if not n:
            return bytes(out)


def crc32c(data):
    crc = 0xFFFFFFFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = (crc >> 1) ^ 0x82F63B78 if crc & 1 else crc >> 1
    return crc ^ 0xFFFFFFFF


def stream(xyz, chunk, order, request="cloud { unit: LENGTH_UNIT_METRE }\n" + CELL):
    chunks = [xyz[i:i + chunk] for i in range(0, len(xyz), chunk)]
    msgs = [encode("PlanPickStreamRequest", "header { request { %s } total_bytes: %d chunk_count: %d crc32c: %d }"
                   % (request, len(xyz), len(chunks), crc32c(xyz)))]
    msgs += [encode("PlanPickStreamRequest", 'chunk { index: %d data: "%s" }' % (i, escaped(chunks[i])))
             for i in order(len(chunks))]
    return b"".join(varint(len(m)) + m for m in msgs)


def requests():
    xyz = packed(POINTS)
    cloud = 'cloud { xyz: "%s" unit: LENGTH_UNIT_METRE }\n' % escaped(xyz)
    options = 'options { profile: "thesis" seed: 17 max_plans: 4 disable_simulation: true }\n'
    write("fuzz_request_validation", "plan_pick_full", b"\x00" + encode("PlanPickRequest", cloud + CELL + options))
    write("fuzz_request_validation", "plan_pick_cloud_only", b"\x00" + encode("PlanPickRequest", cloud))
    mm = 'cloud { xyz: "%s" unit: LENGTH_UNIT_MILLIMETRE }\n' % escaped(packed([(1000 * x, 1000 * y, 1000 * z) for x, y, z in POINTS]))
    write("fuzz_request_validation", "model_tubes_mm", b"\x01" + encode("ModelTubesRequest", mm + CELL))
    write("fuzz_request_validation", "model_tubes_default_cell", b"\x01" + encode("ModelTubesRequest", cloud + options))
    wrench = """reference { force { z: -2.0 } torque { x: 0.01 } }
current { force { z: -2.55 } torque { x: 0.05 y: -0.02 } }
tube_mass: 0.055
tcp_pose { position { z: 0.5 } orientation { x: 1 } }
"""
    write("fuzz_request_validation", "analyze_wrench", b"\x02" + encode("AnalyzeWrenchRequest", wrench))
    write("fuzz_request_validation", "analyze_wrench_variant",
          b"\x02" + encode("AnalyzeWrenchRequest", wrench.replace("tube_mass: 0.055\n", "")
                           + "variant: RESOLUTION_VARIANT_JOINT_SAFE\n"))

    big = packed(POINTS * 3)
    write("fuzz_cloud_stream", "in_order", stream(big, 40, lambda n: range(n)))
    write("fuzz_cloud_stream", "reversed", stream(big, 36, lambda n: reversed(range(n))))
    write("fuzz_cloud_stream", "one_chunk_default_cell", stream(xyz, 1000, lambda n: range(n), "cloud { }"))
    write("fuzz_cloud_stream", "missing_chunk", stream(big, 24, lambda n: range(1, n)))
    write("fuzz_cloud_stream", "raw_xyz", xyz)  # DecodeCloud on the raw input


# --- YAML -----------------------------------------------------------------------------------------
def yaml(build_dir):
    with open(os.path.join(ROOT, "deploy", "cell.example.yaml"), "rb") as f:
        cell = f.read()
    with open(os.path.join(ROOT, "deploy", "cell-controller.example.yaml"), "rb") as f:
        controller = f.read()
    write("fuzz_yaml_config", "cell_example", b"\x01" + cell)
    write("fuzz_yaml_config", "controller_example", b"\x03" + controller)
    write("fuzz_yaml_config", "params_small", b"\x00" + b"modeling:\n  threads: 1\nplanning:\n  simulation_threads: 1\n")
    write("fuzz_yaml_config", "server_small",
          b"\x02server:\n  address: 127.0.0.1:0\n  workers: 2\nplanning:\n  profile: thesis\n  seed: 3\ncell:\n"
          + b"".join(b"  " + line + b"\n" for line in cell.splitlines()))
    tools = [("params_dump", b"\x00", [os.path.join(build_dir, "bin", "tubepick"), "params", "--dump"]),
             ("params_thesis_dump", b"\x00", [os.path.join(build_dir, "bin", "tubepick"), "params", "--profile",
                                               "thesis", "--dump"]),
             ("server_default", b"\x02", [os.path.join(build_dir, "bin", "tubepick-server"), "--print-config"])]
    for name, selector, command in tools:
        if not os.path.exists(command[0]):
            print("make_corpus: %s not built, seed %s skipped" % (command[0], name), file=sys.stderr)
            continue
        write("fuzz_yaml_config", name, selector + subprocess.run(command, stdout=subprocess.PIPE, check=True).stdout)


# --- HSES / RDT -----------------------------------------------------------------------------------
def hses_header(data_size, answer, request_id):
    return (b"YERC" + struct.pack("<HH", 32, data_size) + bytes([3, 1, 1 if answer else 0, request_id])
            + struct.pack("<I", 0x80000000 if answer else 0) + b"99999999")


def hses():
    move = struct.pack("<26i", 1, 0, 1, 1000, 16, 400000, 0, 300000, 1800000, 0, 0, *([0] * 15))
    requests = [
        ("status_read", 0x72, 1, 0, 0x01, b""),
        ("position_read", 0x75, 101, 0, 0x01, b""),
        ("servo_on", 0x83, 2, 1, 0x10, struct.pack("<i", 1)),
        ("move_straight", 0x8A, 2, 1, 0x02, move),
    ]
    for rid, (name, command, instance, attribute, service, data) in enumerate(requests):
        write("fuzz_hses_decode", "request_" + name,
              hses_header(len(data), False, rid) + struct.pack("<HHBB", command, instance, attribute, service)
              + b"\0\0" + data)
    answers = [
        ("status", 0x81, 0, struct.pack("<ii", 0xC2, 0x40)),
        ("position", 0x81, 0, struct.pack("<13i", 16, 0, 0, 0, 0, 400000, 0, 300000, 1800000, -5000, 900000, 0, 0)),
        ("error", 0x90, 0x08, b""),
    ]
    for rid, (name, service, status, data) in enumerate(answers):
        added = 0x2010 if status else 0
        write("fuzz_hses_decode", "answer_" + name,
              hses_header(len(data), True, rid) + bytes([service, status, 2 if status else 0, 0])
              + struct.pack("<H", added) + b"\0\0" + data)


def rdt():
    write("fuzz_rdt_decode", "request_realtime", struct.pack(">HHI", 0x1234, 0x0002, 1))
    write("fuzz_rdt_decode", "request_bias", struct.pack(">HHI", 0x1234, 0x0042, 0))
    write("fuzz_rdt_decode", "record", struct.pack(">III6i", 7, 1234, 0, 1000000, -2000000, 3000000, 100, -200, 300))
    write("fuzz_rdt_decode", "record_status",
          struct.pack(">III6i", 8, 1235, 0x80010000, 0, 0, -1, 2147483647, -2147483648, 5))


def main():
    build_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build")
    if os.path.isdir(CORPUS):
        shutil.rmtree(CORPUS)
    ply()
    pcd()
    requests()
    yaml(build_dir)
    hses()
    rdt()


if __name__ == "__main__":
    main()
