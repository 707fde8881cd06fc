// Writes the MCAP conformance files from their .json with the official MCAP
// library (@mcap/core's record and chunk builders) and checks each against
// the sha256 and size of the Git LFS pointer that stands in its place: a
// file written here is then byte for byte the suite's own.
//
// Usage: node write_mcap_conformance.mjs SUITE_DIR OUT_DIR
//   For every SUITE_DIR/<Case>/<name>.mcap that is an LFS pointer, writes
//   OUT_DIR/<Case>/<name>.mcap; a real .mcap is copied. Prints one line per
//   file that does not match its pointer and exits 1 if there is one.
//
// How a file is written (the suite's writer options, named in the file
// name: ch chunked, mx message indexes, chx chunk index, rsh / rch schemas /
// channels repeated in the summary, st statistics, sum summary offsets, ax /
// mdx attachment / metadata indexes, pad padded records): magic, Header
// (empty profile and library), the data records (in one uncompressed chunk
// with ch, attachments and metadata outside it), the chunk's message
// indexes, DataEnd with the CRC of everything before it, the summary
// groups in the order schemas, channels, statistics, metadata indexes,
// attachment indexes, chunk indexes, then the summary offsets of the
// non-empty groups, the Footer (summary CRC over the summary, the summary
// offsets and the Footer's first fields) and the magic.
import { createHash } from "node:crypto";
import fs from "node:fs";
import path from "node:path";

import { crc32, crc32Final, crc32Init, crc32Update } from "@foxglove/crc";
import { McapChunkBuilder, McapRecordBuilder, Opcode } from "@mcap/core";

const [suiteDir, outDir] = process.argv.slice(2);

function bytes(list) {
  return new Uint8Array(list.map(Number));
}

function map(object) {
  return new Map(Object.entries(object));
}

// The data records of a conformance .json (those before DataEnd), as the
// writer takes them.
function inputRecords(json) {
  const records = [];
  for (const { type, fields: list } of json.records) {
    if (type === "DataEnd") break;
    const f = Object.fromEntries(list);
    switch (type) {
      case "Schema":
        records.push({ type, id: Number(f.id), name: f.name, encoding: f.encoding, data: bytes(f.data) });
        break;
      case "Channel":
        records.push({ type, id: Number(f.id), schemaId: Number(f.schema_id), topic: f.topic,
                       messageEncoding: f.message_encoding, metadata: map(f.metadata) });
        break;
      case "Message":
        records.push({ type, channelId: Number(f.channel_id), sequence: Number(f.sequence),
                       logTime: BigInt(f.log_time), publishTime: BigInt(f.publish_time),
                       data: bytes(f.data) });
        break;
      case "Attachment":
        records.push({ type, name: f.name, logTime: BigInt(f.log_time),
                       createTime: BigInt(f.create_time), mediaType: f.media_type,
                       data: bytes(f.data) });
        break;
      case "Metadata":
        records.push({ type, name: f.name, metadata: map(f.metadata) });
        break;
    }
  }
  return records;
}

function writeFile(features, records) {
  const has = (name) => features.has(name);
  const builder = new McapRecordBuilder({ padRecords: has("pad") });
  builder.writeMagic();
  builder.writeHeader({ profile: "", library: "" });
  const chunk = has("ch") ? new McapChunkBuilder({ useMessageIndex: has("mx") }) : undefined;
  const counts = { message: 0n, channel: 0, schema: 0, attachment: 0, metadata: 0 };
  const channelMessageCounts = new Map();
  let start, end;
  const metadataIndexes = [], attachmentIndexes = [], chunkIndexes = [];
  for (const r of records) {
    if (r.type === "Schema") {
      counts.schema++;
      chunk ? chunk.addSchema(r) : builder.writeSchema(r);
    } else if (r.type === "Channel") {
      counts.channel++;
      chunk ? chunk.addChannel(r) : builder.writeChannel(r);
    } else if (r.type === "Message") {
      counts.message++;
      channelMessageCounts.set(r.channelId, (channelMessageCounts.get(r.channelId) ?? 0n) + 1n);
      chunk ? chunk.addMessage(r) : builder.writeMessage(r);
      if (start === undefined || r.logTime < start) start = r.logTime;
      if (end === undefined || r.logTime > end) end = r.logTime;
    } else if (r.type === "Attachment") {
      counts.attachment++;
      const offset = BigInt(builder.length);
      const length = builder.writeAttachment(r);
      if (has("ax")) {
        attachmentIndexes.push({ name: r.name, length, offset, dataSize: BigInt(r.data.byteLength),
                                 mediaType: r.mediaType, logTime: r.logTime,
                                 createTime: r.createTime });
      }
    } else if (r.type === "Metadata") {
      counts.metadata++;
      const offset = BigInt(builder.length);
      const length = builder.writeMetadata(r);
      if (has("mdx")) metadataIndexes.push({ name: r.name, length, offset });
    }
  }
  if (chunk) {
    const chunkStartOffset = BigInt(builder.length);
    const size = BigInt(chunk.buffer.byteLength);
    const chunkLength = builder.writeChunk({
      compression: "", messageStartTime: chunk.messageStartTime,
      messageEndTime: chunk.messageEndTime, uncompressedCrc: crc32(chunk.buffer),
      uncompressedSize: size, records: chunk.buffer });
    const messageIndexOffsets = new Map();
    let messageIndexLength = 0n;
    for (const index of chunk.indices) {
      messageIndexOffsets.set(index.channelId, BigInt(builder.length));
      messageIndexLength += builder.writeMessageIndex(index);
    }
    if (has("chx")) {
      chunkIndexes.push({ compression: "", messageStartTime: chunk.messageStartTime,
                          messageEndTime: chunk.messageEndTime, uncompressedSize: size,
                          compressedSize: size, chunkStartOffset, chunkLength,
                          messageIndexLength, messageIndexOffsets });
    }
  }
  builder.writeDataEnd({ dataSectionCrc: crc32(builder.buffer) });

  const summaryStart = BigInt(builder.length);
  const groups = [];  // [opcode, start, length]
  const group = (opcode, write) => {
    const groupStart = BigInt(builder.length);
    write();
    groups.push([opcode, groupStart, BigInt(builder.length) - groupStart]);
  };
  group(Opcode.SCHEMA, () => {
    if (has("rsh")) for (const r of records) if (r.type === "Schema") builder.writeSchema(r);
  });
  group(Opcode.CHANNEL, () => {
    if (has("rch")) for (const r of records) if (r.type === "Channel") builder.writeChannel(r);
  });
  group(Opcode.STATISTICS, () => {
    if (!has("st")) return;
    builder.writeStatistics({
      messageCount: counts.message, channelCount: counts.channel, schemaCount: counts.schema,
      attachmentCount: counts.attachment, metadataCount: counts.metadata,
      chunkCount: chunk ? 1 : 0, messageStartTime: start ?? 0n, messageEndTime: end ?? 0n,
      channelMessageCounts });
  });
  group(Opcode.METADATA_INDEX, () => metadataIndexes.forEach((r) => builder.writeMetadataIndex(r)));
  group(Opcode.ATTACHMENT_INDEX,
        () => attachmentIndexes.forEach((r) => builder.writeAttachmentIndex(r)));
  group(Opcode.CHUNK_INDEX, () => chunkIndexes.forEach((r) => builder.writeChunkIndex(r)));
  const hasSummary = BigInt(builder.length) !== summaryStart;
  let summaryOffsetStart = 0n;
  if (has("sum")) {
    summaryOffsetStart = BigInt(builder.length);
    for (const [groupOpcode, groupStart, groupLength] of groups) {
      if (groupLength !== 0n) builder.writeSummaryOffset({ groupOpcode, groupStart, groupLength });
    }
  }
  const all = builder.buffer;
  let summaryCrc = crc32Update(crc32Init(),
                               all.subarray(Number(summaryStart), all.byteLength));
  const footerStart = new DataView(new ArrayBuffer(1 + 8 + 8 + 8));
  footerStart.setUint8(0, Opcode.FOOTER);
  footerStart.setBigUint64(1, 8n + 8n + 4n, true);
  footerStart.setBigUint64(9, hasSummary ? summaryStart : 0n, true);
  footerStart.setBigUint64(17, summaryOffsetStart, true);
  summaryCrc = crc32Final(crc32Update(summaryCrc, footerStart));
  builder.writeFooter({ summaryStart: hasSummary ? summaryStart : 0n, summaryOffsetStart,
                        summaryCrc });
  builder.writeMagic();
  return builder.buffer;
}

let mismatches = 0;
for (const caseName of fs.readdirSync(suiteDir).sort()) {
  const caseDir = path.join(suiteDir, caseName);
  if (!fs.statSync(caseDir).isDirectory()) continue;
  fs.mkdirSync(path.join(outDir, caseName), { recursive: true });
  for (const file of fs.readdirSync(caseDir).sort()) {
    if (!file.endsWith(".mcap")) continue;
    const source = path.join(caseDir, file);
    const target = path.join(outDir, caseName, file);
    const stored = fs.readFileSync(source);
    const pointer = /^version https:\/\/git-lfs\.github\.com\/spec\/v1\noid sha256:([0-9a-f]{64})\nsize (\d+)\n/
      .exec(stored.toString("latin1"));
    if (!pointer) {
      fs.writeFileSync(target, stored);
      continue;
    }
    const json = JSON.parse(fs.readFileSync(source.replace(/\.mcap$/, ".json"), "utf8"));
    const features = new Set(file.replace(/\.mcap$/, "").split("-").slice(1));
    const data = writeFile(features, inputRecords(json));
    const sha256 = createHash("sha256").update(data).digest("hex");
    if (sha256 !== pointer[1] || data.byteLength !== Number(pointer[2])) {
      console.log(`${source}: written ${data.byteLength} bytes sha256 ${sha256}, the pointer ` +
                  `says ${pointer[2]} bytes sha256 ${pointer[1]}`);
      mismatches++;
    }
    fs.writeFileSync(target, data);
  }
}
process.exit(mismatches === 0 ? 0 : 1);
