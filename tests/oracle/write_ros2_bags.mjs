// Writes ROS 2 bags with the public reference libraries (not the project's
// code), as an oracle for the tests of bag/ros2 and bag/mcap:
//   MCAP:            @mcap/core McapWriter (+ @mcap/nodejs file handle),
//                    chunks uncompressed, lz4 (lz4js frames) or zstd
//                    (@foxglove/wasm-zstd), with or without the summary;
//   rosbag2 sqlite3: sql.js (the SQLite library compiled to WebAssembly, no
//                    native build), the rosbag2 schema (topics, messages),
//                    each database built in memory and written whole to its
//                    .db3 file, metadata.yaml beside the .db3 files;
//   CDR:             @foxglove/rosmsg2-serialization MessageWriter (little
//                    endian), or @foxglove/cdr CdrWriter with the big-endian
//                    encapsulation (the MessageWriter writes little endian only);
//   ROS 1 in MCAP:   --encoding=ros1: profile "ros1", schemas "ros1msg",
//                    messages "ros1" by @foxglove/rosmsg-serialization
//                    MessageWriter, ROS 1 type names (sensor_msgs/Imu), a
//                    header seq of 0 (as a ROS 1 bag converted to MCAP).
//
// Usage:
//   node write_ros2_bags.mjs OUT --format=mcap|sqlite3 [--compression=none|lz4|zstd]
//        [--no-summary] [--no-chunks] [--big-endian] [--encoding=cdr|ros1] [--split=N] [--messages=IN.jsonl]
//        [--expected=EXPECTED.txt]
// OUT is the .mcap file, or the rosbag2 folder (metadata.yaml + OUT_i.db3; a
// new .db3 every N messages with --split=N).
// Without --messages the content is deterministic: 40 sensor_msgs/msg/Imu on
// /imu, 3 PointCloud2 in each of the Velodyne (/velodyne_points), Ouster
// (/ouster/points) and Hesai (/hesai/pandar) layouts, 5 std_msgs/msg/String on
// /chatter, interleaved in record time. --messages reads one JSON object per
// line instead: {"topic", "type" ("sensor_msgs/msg/Imu" | "sensor_msgs/msg/PointCloud2" |
// "livox_ros_driver2/msg/CustomMsg" | "livox_interfaces/msg/CustomMsg" |
// "tf2_msgs/msg/TFMessage" (CDR only)), "record_ns"
// (string), "msg": the message with stamps as {sec, nanosec}, the cloud's data
// in base64 as "data_b64", a CustomMsg's timebase as a string and its points
// in base64 as "points_b64" (19 bytes each, the ROS 1 wire form)}.
// --expected writes what was serialized, one line per message in record order:
//   imu TOPIC RECORD_NS SEC NANOSEC frame=FRAME 37 doubles (orientation xyzw,
//       its covariance, angular velocity, covariance, linear acceleration, covariance)
//   cloud TOPIC RECORD_NS SEC NANOSEC frame=FRAME HEIGHT WIDTH BIGENDIAN POINT_STEP
//       ROW_STEP DENSE NFIELDS (NAME OFFSET DATATYPE COUNT)... DATA_HEX
//   livox TOPIC RECORD_NS SEC NANOSEC frame=FRAME TIMEBASE POINT_NUM LIDAR_ID N
//       (OFFSET_TIME X Y Z REFLECTIVITY TAG LINE)...
//   string TOPIC RECORD_NS DATA
// Doubles are printed by JavaScript's shortest round-trip form.

import fs from "node:fs";
import path from "node:path";
import { open } from "node:fs/promises";
import readline from "node:readline";

import initSqlJs from "sql.js";
import { CdrWriter, EncapsulationKind } from "@foxglove/cdr";
import { McapWriter } from "@mcap/core";
import { FileHandleWritable } from "@mcap/nodejs";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { MessageWriter as Ros1MessageWriter } from "@foxglove/rosmsg-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "lz4js";

const SEP = "\n================================================================================\n";
const HEADER_DEFS =
  "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id" + SEP +
  "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec";
const DEFINITIONS = {
  "sensor_msgs/msg/Imu":
    "std_msgs/Header header\n" +
    "geometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n" +
    "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n" +
    "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance" +
    SEP + HEADER_DEFS + SEP +
    "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1" + SEP +
    "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z",
  "sensor_msgs/msg/PointCloud2":
    "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n" +
    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense" +
    SEP + HEADER_DEFS + SEP +
    "MSG: sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\n" +
    "uint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\n" +
    "string name\nuint32 offset\nuint8 datatype\nuint32 count",
  "std_msgs/msg/String": "string data",
  "livox_ros_driver2/msg/CustomMsg":
    "std_msgs/Header header\nuint64 timebase\nuint32 point_num\nuint8 lidar_id\nuint8[3] rsvd\n" +
    "livox_ros_driver2/CustomPoint[] points" + SEP + HEADER_DEFS + SEP +
    "MSG: livox_ros_driver2/CustomPoint\nuint32 offset_time\nfloat32 x\nfloat32 y\nfloat32 z\n" +
    "uint8 reflectivity\nuint8 tag\nuint8 line",
};
DEFINITIONS["tf2_msgs/msg/TFMessage"] =
  "geometry_msgs/TransformStamped[] transforms" + SEP +
  "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n" +
  "geometry_msgs/Transform transform" + SEP + HEADER_DEFS + SEP +
  "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\n" +
  "geometry_msgs/Quaternion rotation" + SEP +
  "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z" + SEP +
  "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1";
// livox_interfaces (livox_ros2_driver) has the same fields.
DEFINITIONS["livox_interfaces/msg/CustomMsg"] = DEFINITIONS["livox_ros_driver2/msg/CustomMsg"]
  .replaceAll("livox_ros_driver2/", "livox_interfaces/");
const isLivox = (type) => type.endsWith("/msg/CustomMsg");
// The same messages in ROS 1 (std_msgs/Header with seq, time as sec/nsec).
const ROS1_HEADER = "MSG: std_msgs/Header\nuint32 seq\ntime stamp\nstring frame_id";
const ROS1_DEFINITIONS = {
  "sensor_msgs/Imu":
    "Header header\n" +
    "geometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n" +
    "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n" +
    "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance" +
    SEP + ROS1_HEADER + SEP +
    "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w" + SEP +
    "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z",
  "sensor_msgs/PointCloud2":
    "Header header\nuint32 height\nuint32 width\nPointField[] fields\n" +
    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense" +
    SEP + ROS1_HEADER + SEP +
    "MSG: sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\n" +
    "uint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\n" +
    "string name\nuint32 offset\nuint8 datatype\nuint32 count",
  "std_msgs/String": "string data",
};
const ros1TypeOf = (type) => type.replace("/msg/", "/");

function parseArgs(argv) {
  const args = { out: null, format: "mcap", compression: "none", summary: true, chunks: true,
                 bigEndian: false, encoding: "cdr", split: 0, messages: null, expected: null };
  for (const a of argv) {
    if (!a.startsWith("--")) args.out = a;
    else if (a.startsWith("--format=")) args.format = a.slice(9);
    else if (a.startsWith("--compression=")) args.compression = a.slice(14);
    else if (a === "--no-summary") args.summary = false;
    else if (a === "--no-chunks") args.chunks = false;
    else if (a === "--big-endian") args.bigEndian = true;
    else if (a.startsWith("--encoding=")) args.encoding = a.slice(11);
    else if (a.startsWith("--split=")) args.split = Number(a.slice(8));
    else if (a.startsWith("--messages=")) args.messages = a.slice(11);
    else if (a.startsWith("--expected=")) args.expected = a.slice(11);
    else throw new Error("unknown argument " + a);
  }
  if (!args.out || !["mcap", "sqlite3"].includes(args.format) ||
      !["none", "lz4", "zstd"].includes(args.compression) ||
      !["cdr", "ros1"].includes(args.encoding) || (args.encoding === "ros1" && args.format !== "mcap")) {
    throw new Error("usage: write_ros2_bags.mjs OUT --format=mcap|sqlite3 [options]");
  }
  return args;
}

// mulberry32: a small deterministic PRNG, uniform in [0, 1).
function Rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

const stampOf = (ns) => ({ sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) });

function makeImu(rng, stampNs) {
  const v = (s) => (rng() - 0.5) * s;
  const cov = () => Array.from({ length: 9 }, () => v(1e-3));
  return {
    header: { stamp: stampOf(stampNs), frame_id: "imu_link" },
    orientation: { x: v(1), y: v(1), z: v(1), w: v(1) },
    orientation_covariance: cov(),
    angular_velocity: { x: v(2), y: v(2), z: v(2) },
    angular_velocity_covariance: cov(),
    linear_acceleration: { x: v(4), y: v(4), z: 9.81 + v(1) },
    linear_acceleration_covariance: cov(),
  };
}

const field = (name, offset, datatype) => ({ name, offset, datatype, count: 1 });
// The three layouts of tests/oracle/write_test_bags.py.
const LAYOUTS = {
  velodyne: { frame: "velodyne", height: 1, width: 16 * 20, step: 22, rowPad: 0,
    fields: [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7), field("intensity", 12, 7),
             field("ring", 16, 4), field("time", 18, 7)] },
  ouster: { frame: "os_sensor", height: 16, width: 16, step: 48, rowPad: 16,
    fields: [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7), field("intensity", 16, 7),
             field("t", 20, 6), field("reflectivity", 24, 4), field("ring", 26, 2),
             field("ambient", 28, 4), field("range", 32, 6)] },
  hesai: { frame: "hesai_lidar", height: 1, width: 32 * 10, step: 26, rowPad: 0,
    fields: [field("x", 0, 7), field("y", 4, 7), field("z", 8, 7), field("intensity", 12, 7),
             field("ring", 16, 4), field("timestamp", 18, 8)] },
};

function makeCloud(kind, rng, stampNs) {
  const L = LAYOUTS[kind];
  const rowStep = L.step * L.width + L.rowPad;
  const data = new Uint8Array(rowStep * L.height);
  const view = new DataView(data.buffer);
  for (let row = 0; row < L.height; ++row) {
    for (let col = 0; col < L.width; ++col) {
      const o = row * rowStep + col * L.step;
      const nan = rng() < 0.05;
      for (let i = 0; i < 3; ++i) view.setFloat32(o + 4 * i, nan ? NaN : (rng() - 0.5) * 60, true);
      if (kind === "velodyne") {
        view.setFloat32(o + 12, rng() * 255, true);
        view.setUint16(o + 16, col % 16, true);
        view.setFloat32(o + 18, -0.1 + col * 3e-4, true);
      } else if (kind === "ouster") {
        view.setFloat32(o + 16, rng() * 3000, true);
        view.setUint32(o + 20, col * 1562500 + row * 7, true);
        view.setUint16(o + 24, 77, true);
        data[o + 26] = row;
        view.setUint16(o + 28, 123, true);
        view.setUint32(o + 32, 4567, true);
      } else {
        view.setFloat32(o + 12, rng() * 255, true);
        view.setUint16(o + 16, col % 32, true);
        view.setFloat64(o + 18, Number(stampNs) / 1e9 + col * 1e-4, true);
      }
    }
  }
  return {
    header: { stamp: stampOf(stampNs), frame_id: L.frame },
    height: L.height, width: L.width, fields: L.fields, is_bigendian: false,
    point_step: L.step, row_step: rowStep, data, is_dense: false,
  };
}

// The deterministic content: [{topic, type, recordNs (BigInt), msg}] in record order.
function deterministicMessages() {
  const rng = Rng(16);
  const out = [];
  const t0 = 1700000000000000000n;
  for (let i = 0; i < 40; ++i) {
    const stamp = t0 + BigInt(i) * 5000000n;
    out.push({ topic: "/imu", type: "sensor_msgs/msg/Imu", recordNs: stamp + 1000000n,
               msg: makeImu(rng, stamp) });
  }
  const clouds = [["velodyne", "/velodyne_points"], ["ouster", "/ouster/points"],
                  ["hesai", "/hesai/pandar"]];
  for (let i = 0; i < 3; ++i) {
    clouds.forEach(([kind, topic], k) => {
      const stamp = t0 + BigInt(i) * 60000000n + BigInt(k) * 1000000n;
      out.push({ topic, type: "sensor_msgs/msg/PointCloud2", recordNs: stamp + 30000000n,
                 msg: makeCloud(kind, rng, stamp) });
    });
  }
  for (let i = 0; i < 5; ++i) {
    out.push({ topic: "/chatter", type: "std_msgs/msg/String",
               recordNs: t0 + BigInt(i) * 33000000n + 7n, msg: { data: "Hello, world! " + i } });
  }
  // Stable sort by record time (equal times keep their order).
  return out.map((m, i) => [m, i])
    .sort((a, b) => (a[0].recordNs < b[0].recordNs ? -1 : a[0].recordNs > b[0].recordNs ? 1 : a[1] - b[1]))
    .map(([m]) => m);
}

// The messages of a JSON-lines file, one at a time (the file may be larger
// than memory).
async function* messagesFromJsonl(file) {
  const lines = readline.createInterface({ input: fs.createReadStream(file), crlfDelay: Infinity });
  for await (const line of lines) {
    if (line.trim() === "") continue;
    const j = JSON.parse(line);
    if (j.msg.data_b64 !== undefined) {
      j.msg.data = new Uint8Array(Buffer.from(j.msg.data_b64, "base64"));
      delete j.msg.data_b64;
    }
    if (j.msg.points_b64 !== undefined) {
      j.msg.points = livoxPointsFromBytes(Buffer.from(j.msg.points_b64, "base64"));
      j.msg.timebase = BigInt(j.msg.timebase);
      delete j.msg.points_b64;
    }
    yield { topic: j.topic, type: j.type, recordNs: BigInt(j.record_ns), msg: j.msg };
  }
}

// Livox CustomPoints from their ROS 1 wire form (19 bytes each, little endian).
function livoxPointsFromBytes(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const points = [];
  for (let o = 0; o + 19 <= bytes.byteLength; o += 19) {
    points.push({ offset_time: view.getUint32(o, true), x: view.getFloat32(o + 4, true),
                  y: view.getFloat32(o + 8, true), z: view.getFloat32(o + 12, true),
                  reflectivity: bytes[o + 16], tag: bytes[o + 17], line: bytes[o + 18] });
  }
  return points;
}

// Big-endian CDR with the CdrWriter; alignment is the library's.
function writeBigEndian(type, m) {
  const w = new CdrWriter({ kind: EncapsulationKind.CDR_BE });
  const header = (h) => { w.int32(h.stamp.sec); w.uint32(h.stamp.nanosec); w.string(h.frame_id); };
  if (type === "sensor_msgs/msg/Imu") {
    header(m.header);
    const o = m.orientation;
    [o.x, o.y, o.z, o.w].forEach((v) => w.float64(v));
    w.float64Array(m.orientation_covariance, false);
    for (const [vec, cov] of [[m.angular_velocity, m.angular_velocity_covariance],
                              [m.linear_acceleration, m.linear_acceleration_covariance]]) {
      [vec.x, vec.y, vec.z].forEach((v) => w.float64(v));
      w.float64Array(cov, false);
    }
  } else if (type === "sensor_msgs/msg/PointCloud2") {
    header(m.header);
    w.uint32(m.height); w.uint32(m.width);
    w.sequenceLength(m.fields.length);
    for (const f of m.fields) { w.string(f.name); w.uint32(f.offset); w.uint8(f.datatype); w.uint32(f.count); }
    w.uint8(m.is_bigendian ? 1 : 0); w.uint32(m.point_step); w.uint32(m.row_step);
    w.uint8Array(m.data, true);
    w.uint8(m.is_dense ? 1 : 0);
  } else if (isLivox(type)) {
    header(m.header);
    w.uint64(m.timebase); w.uint32(m.point_num); w.uint8(m.lidar_id);
    for (const b of m.rsvd) w.uint8(b);
    w.sequenceLength(m.points.length);
    for (const p of m.points) {
      w.uint32(p.offset_time); w.float32(p.x); w.float32(p.y); w.float32(p.z);
      w.uint8(p.reflectivity); w.uint8(p.tag); w.uint8(p.line);
    }
  } else {
    w.string(m.data);
  }
  return w.data;
}

// ROS 1 serialization of a message given in the ROS 2 form of this script.
function makeRos1Serializer() {
  const writers = {};
  for (const [type, text] of Object.entries(ROS1_DEFINITIONS)) {
    writers[type] = new Ros1MessageWriter(parse(text));
  }
  return (type, msg) => {
    const m = msg.header === undefined ? msg : { ...msg, header: { seq: 0,
      stamp: { sec: msg.header.stamp.sec, nsec: msg.header.stamp.nanosec },
      frame_id: msg.header.frame_id } };
    return writers[ros1TypeOf(type)].writeMessage(m);
  };
}

function makeSerializer(bigEndian) {
  const writers = {};
  for (const [type, text] of Object.entries(DEFINITIONS)) {
    writers[type] = new MessageWriter(parse(text, { ros2: true }));
  }
  return (type, msg) => (bigEndian ? writeBigEndian(type, msg) : writers[type].writeMessage(msg));
}

function expectedLine(m) {
  const h = m.msg.header;
  if (m.type === "sensor_msgs/msg/Imu") {
    const x = m.msg;
    const values = [x.orientation.x, x.orientation.y, x.orientation.z, x.orientation.w,
      ...x.orientation_covariance, x.angular_velocity.x, x.angular_velocity.y, x.angular_velocity.z,
      ...x.angular_velocity_covariance, x.linear_acceleration.x, x.linear_acceleration.y,
      x.linear_acceleration.z, ...x.linear_acceleration_covariance];
    return `imu ${m.topic} ${m.recordNs} ${h.stamp.sec} ${h.stamp.nanosec} frame=${h.frame_id} ` +
      values.map((v) => String(v)).join(" ");
  }
  if (m.type === "sensor_msgs/msg/PointCloud2") {
    const c = m.msg;
    const fields = c.fields.map((f) => `${f.name} ${f.offset} ${f.datatype} ${f.count}`).join(" ");
    return `cloud ${m.topic} ${m.recordNs} ${h.stamp.sec} ${h.stamp.nanosec} frame=${h.frame_id} ` +
      `${c.height} ${c.width} ${c.is_bigendian ? 1 : 0} ${c.point_step} ${c.row_step} ` +
      `${c.is_dense ? 1 : 0} ${c.fields.length} ${fields} ${Buffer.from(c.data).toString("hex")}`;
  }
  if (isLivox(m.type)) {
    const c = m.msg;
    const f = (v) => (Number.isNaN(v) ? "nan" : String(v));
    return `livox ${m.topic} ${m.recordNs} ${h.stamp.sec} ${h.stamp.nanosec} frame=${h.frame_id} ` +
      `${c.timebase} ${c.point_num} ${c.lidar_id} ${c.points.length} ` +
      c.points.map((p) => `${p.offset_time} ${f(p.x)} ${f(p.y)} ${f(p.z)} ${p.reflectivity} ` +
                          `${p.tag} ${p.line}`).join(" ");
  }
  return `string ${m.topic} ${m.recordNs} ${m.msg.data}`;
}

async function writeMcap(args, messages, serialize, onMessage) {
  let compressChunk;
  if (args.compression === "lz4") {
    compressChunk = (data) => ({ compression: "lz4", compressedData: lz4.compress(data) });
  } else if (args.compression === "zstd") {
    await zstd.isLoaded;
    compressChunk = (data) => ({ compression: "zstd", compressedData: zstd.compress(data, 3) });
  }
  const handle = await open(args.out, "w");
  const writer = new McapWriter({
    writable: new FileHandleWritable(handle),
    chunkSize: 64 * 1024,
    useChunks: args.chunks,
    compressChunk,
    useStatistics: args.summary, useSummaryOffsets: args.summary, useChunkIndex: args.summary,
    useMessageIndex: args.summary, repeatSchemas: args.summary, repeatChannels: args.summary,
    useAttachmentIndex: args.summary, useMetadataIndex: args.summary,
  });
  const ros1 = args.encoding === "ros1";
  await writer.start({ profile: ros1 ? "ros1" : "ros2",
                       library: "tiltcal tests/oracle/write_ros2_bags.mjs" });
  const channels = new Map();
  const sequences = new Map();
  for await (const m of messages) {
    onMessage(m);
    if (!channels.has(m.topic)) {
      const name = ros1 ? ros1TypeOf(m.type) : m.type;
      const schemaId = await writer.registerSchema({
        name, encoding: ros1 ? "ros1msg" : "ros2msg",
        data: new TextEncoder().encode((ros1 ? ROS1_DEFINITIONS : DEFINITIONS)[name]) });
      channels.set(m.topic, await writer.registerChannel({
        topic: m.topic, schemaId, messageEncoding: ros1 ? "ros1" : "cdr", metadata: new Map() }));
      sequences.set(m.topic, 0);
    }
    const sequence = sequences.get(m.topic);
    sequences.set(m.topic, sequence + 1);
    await writer.addMessage({ channelId: channels.get(m.topic), sequence, logTime: m.recordNs,
                              publishTime: m.recordNs, data: serialize(m.type, m.msg) });
  }
  await writer.end();
  await handle.close();
}

const QOS = "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 0\n" +
  "    nsec: 0\n  lifespan:\n    sec: 0\n    nsec: 0\n  liveliness: 1\n  liveliness_lease_duration:\n" +
  "    sec: 0\n    nsec: 0\n  avoid_ros_namespace_conventions: false";

// One .db3 of a rosbag2 folder: the rosbag2 schema, topics added as their
// first message comes, ids counted down from 100 so that they do not line up
// with the order of the names. sql.js keeps the database in memory; close()
// writes its image (db.export()) to the file.
class Db3File {
  constructor(SQL, file) {
    this.file = file;
    this.db = new SQL.Database();
    this.db.exec("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);" +
      "INSERT INTO schema VALUES (3, 'humble');" +
      "CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL);" +
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, " +
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);" +
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, " +
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);" +
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);");
    this.insertTopic = this.db.prepare("INSERT INTO topics VALUES (?, ?, ?, 'cdr', ?)");
    this.insertMessage = this.db.prepare("INSERT INTO messages(topic_id, timestamp, data) VALUES (?, ?, ?)");
    this.ids = new Map();
    this.db.exec("BEGIN");
  }
  add(m, data) {
    if (!this.ids.has(m.topic)) {
      this.ids.set(m.topic, 100 - this.ids.size);
      this.insertTopic.run([this.ids.get(m.topic), m.topic, m.type, QOS]);
    }
    // The record time as a BigInt (a 64-bit integer; ns since the epoch pass
    // 2^53), the data as a Uint8Array (a blob).
    this.insertMessage.run([this.ids.get(m.topic), m.recordNs, data]);
  }
  close() {
    this.db.exec("COMMIT");
    this.insertTopic.free();
    this.insertMessage.free();
    fs.writeFileSync(this.file, this.db.export());
    this.db.close();
  }
}

async function writeSqlite(args, messages, serialize, onMessage) {
  fs.rmSync(args.out, { recursive: true, force: true });
  fs.mkdirSync(args.out, { recursive: true });
  const SQL = await initSqlJs();
  const base = path.basename(args.out);
  const topics = new Map();  // name -> {type, count}, in order of first message
  const files = [];
  let db = null;
  let inFile = 0;
  let count = 0;
  let first = 0n;
  let last = 0n;
  for await (const m of messages) {
    onMessage(m);
    if (db === null || (args.split > 0 && inFile === args.split)) {
      if (db !== null) db.close();
      files.push(`${base}_${files.length}.db3`);
      db = new Db3File(SQL, path.join(args.out, files[files.length - 1]));
      inFile = 0;
    }
    db.add(m, serialize(m.type, m.msg));
    ++inFile;
    if (count++ === 0) first = m.recordNs;
    last = m.recordNs;
    if (!topics.has(m.topic)) topics.set(m.topic, { type: m.type, count: 0 });
    topics.get(m.topic).count++;
  }
  if (db !== null) db.close();
  const yaml = ["rosbag2_bagfile_information:", "  version: 5", "  storage_identifier: sqlite3",
    "  relative_file_paths:", ...files.map((f) => `    - ${f}`),
    "  duration:", `    nanoseconds: ${last - first}`,
    "  starting_time:", `    nanoseconds_since_epoch: ${first}`,
    `  message_count: ${count}`, "  topics_with_message_count:",
    ...[...topics].flatMap(([name, t]) => ["    - topic_metadata:", `        name: ${name}`,
      `        type: ${t.type}`, "        serialization_format: cdr",
      `        offered_qos_profiles: ${JSON.stringify(QOS)}`, `      message_count: ${t.count}`]),
    '  compression_format: ""', '  compression_mode: ""', ""];
  fs.writeFileSync(path.join(args.out, "metadata.yaml"), yaml.join("\n"));
}

async function main() {
  const args = parseArgs(process.argv.slice(2));
  const messages = args.messages ? messagesFromJsonl(args.messages) : deterministicMessages();
  const serialize = args.encoding === "ros1" ? makeRos1Serializer() : makeSerializer(args.bigEndian);
  const expected = args.expected ? fs.openSync(args.expected, "w") : null;
  const onMessage = (m) => { if (expected !== null) fs.writeSync(expected, expectedLine(m) + "\n"); };
  if (args.format === "mcap") await writeMcap(args, messages, serialize, onMessage);
  else await writeSqlite(args, messages, serialize, onMessage);
  if (expected !== null) fs.closeSync(expected);
}

main().catch((e) => {
  process.stderr.write(`write_ros2_bags.mjs: ${e.stack || e}\n`);
  process.exit(1);
});
