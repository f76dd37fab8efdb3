// Reads a bag `sonarbench export` wrote with the MCAP project's own TypeScript reader
// (@mcap/core) and decodes its messages with Foxglove's ROS 2 deserialiser, then checks them
// against the dataset the bag came from: counts, schemas, time stamps, and the first beam and
// pose field by field. Usage: node check_rosbag.cjs BAG.mcap DATASET_DIR
"use strict";
const fs = require("fs");
const path = require("path");
const { McapIndexedReader } = require("@mcap/core");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

const [bagPath, datasetDir] = process.argv.slice(2);
let failures = 0;
function check(ok, what) {
  if (!ok) {
    failures += 1;
    console.error(`FAIL ${what}`);
  }
}
function near(a, b, tolerance, what) {
  check(Math.abs(a - b) <= tolerance, `${what}: ${a} against ${b} (tolerance ${tolerance})`);
}

// The dataset's first beam (beams/sweep_0000.bin) and its TUM pose lines.
function firstBeam() {
  const b = fs.readFileSync(path.join(datasetDir, "beams/sweep_0000.bin"));
  const bins = b.readUInt32LE(12 + 24);
  return {
    time: b.readDoubleLE(12),
    head: b.readDoubleLE(20),
    bin: b.readDoubleLE(28),
    intensities: b.subarray(40, 40 + bins),
  };
}
function tum(file) {
  const lines = fs.readFileSync(path.join(datasetDir, file), "utf8").split("\n");
  return lines.filter((l) => l && !l.startsWith("#")).map((l) => l.split(" ").map(Number));
}
function seconds(stamp) {
  return stamp.sec + stamp.nanosec * 1e-9;
}

async function main() {
  const fd = await fs.promises.open(bagPath, "r");
  const size = (await fd.stat()).size;
  const readable = {
    size: async () => BigInt(size),
    read: async (offset, length) => {
      const buffer = new Uint8Array(Number(length));
      await fd.read(buffer, 0, Number(length), Number(offset));
      return buffer;
    },
  };
  const reader = await McapIndexedReader.Initialize({ readable });
  const manifest = JSON.parse(fs.readFileSync(path.join(datasetDir, "manifest.json"), "utf8"));
  const simulated = manifest.source === "simulate";
  const beams = manifest.beams;

  check(reader.header.profile === "ros2", `profile ${reader.header.profile}`);
  check(reader.chunkIndexes.length > 0, "a chunk index");
  check(reader.statistics !== undefined, "a statistics record");
  const expected = {
    "/sonar/image": ["marine_acoustic_msgs/msg/ProjectedSonarImage", beams],
    "/tf": ["tf2_msgs/msg/TFMessage", beams],
    "/tf_static": ["tf2_msgs/msg/TFMessage", 1],
  };
  if (simulated) {
    expected["/ground_truth/pose"] = ["geometry_msgs/msg/PoseStamped", beams];
    expected["/sonar/labels/path"] = ["marine_acoustic_msgs/msg/ProjectedSonarImage", beams];
    expected["/sonar/labels/points"] = ["sensor_msgs/msg/PointCloud2", beams];
  }
  const maxRange = manifest.sensor.num_bins * manifest.sensor.bin_size_m;
  let points = 0;
  const decoders = new Map();
  check(reader.channelsById.size === Object.keys(expected).length, "channel count");
  for (const [id, channel] of reader.channelsById) {
    const schema = reader.schemasById.get(channel.schemaId);
    const want = expected[channel.topic];
    check(want !== undefined, `unexpected topic ${channel.topic}`);
    if (!want) continue;
    check(schema.name === want[0], `${channel.topic} schema ${schema.name}`);
    check(schema.encoding === "ros2msg" && channel.messageEncoding === "cdr", "encodings");
    const text = new TextDecoder().decode(schema.data);
    decoders.set(id, new MessageReader(parse(text, { ros2: true })));
    const count = Number(reader.statistics.channelMessageCounts.get(id));
    check(count === want[1], `${channel.topic}: ${count} messages, expected ${want[1]}`);
  }

  const beam = firstBeam();
  const sonar = tum("poses/sonar.tum");
  const seen = {};
  let lastStamp = -1;
  for await (const message of reader.readMessages()) {
    const channel = reader.channelsById.get(message.channelId);
    const decoder = decoders.get(message.channelId);
    const decoded = decoder.readMessage(message.data);
    check(!decoder.lastReadHadTrailingBytes(), `${channel.topic}: bytes past the schema's fields`);
    const n = (seen[channel.topic] = (seen[channel.topic] || 0) + 1);
    const header = channel.topic.startsWith("/tf") ? decoded.transforms[0].header : decoded.header;
    check(BigInt(header.stamp.sec) * 1000000000n + BigInt(header.stamp.nanosec) === message.logTime,
          `${channel.topic} message ${n}: header stamp equals the log time`);
    check(message.logTime >= lastStamp, "log times in order");
    lastStamp = message.logTime;
    if (channel.topic === "/sonar/image" && n === 1) {
      near(seconds(header.stamp), beam.time, 1e-9, "first beam's time");
      check(header.frame_id === "sonar", `frame ${header.frame_id}`);
      const dir = decoded.beam_directions[0];
      near(Math.atan2(dir.y, dir.x), beam.head > Math.PI ? beam.head - 2 * Math.PI : beam.head,
           1e-12, "head angle");
      check(decoded.ranges.length === beam.intensities.length, "one range a bin");
      decoded.ranges.forEach((r, k) => near(r, (k + 0.5) * beam.bin, 1e-6, `ranges[${k}]`));
      check(Buffer.compare(Buffer.from(decoded.image.data), beam.intensities) === 0,
            "intensities byte for byte");
      check(decoded.image.dtype === 0 && decoded.image.beam_count === 1, "uint8, one beam");
      near(decoded.ping_info.tx_beamwidths[0], manifest.sensor.beam_width_vertical_deg * Math.PI / 180, 1e-6, "vertical width");
      near(decoded.ping_info.rx_beamwidths[0], manifest.sensor.beam_width_horizontal_deg * Math.PI / 180, 1e-6, "horizontal width");
    }
    if (channel.topic === "/sonar/labels/path") {
      check(decoded.image.data.every((v) => v < 7), `${channel.topic} ${n}: a path index 0-6 a bin`);
      check(decoded.ranges.length === manifest.sensor.num_bins, `${channel.topic} ${n}: a range a bin`);
    }
    if (channel.topic === "/sonar/labels/points") {
      // x, y, z (float32), mesh (uint16), direct_share (uint8), 16 bytes a point, in the sonar
      // frame, within the beam's reach.
      const names = decoded.fields.map((f) => `${f.name}@${f.offset}:${f.datatype}`).join(",");
      check(names === "x@0:7,y@4:7,z@8:7,mesh@12:4,direct_share@14:2", `fields ${names}`);
      check(decoded.point_step === 16 && decoded.data.length === 16 * decoded.width &&
            decoded.height === 1 && header.frame_id === "sonar", `${channel.topic} ${n}: layout`);
      const view = new DataView(decoded.data.buffer, decoded.data.byteOffset, decoded.data.length);
      for (let i = 0; i < decoded.width; ++i) {
        const [x, y, z] = [0, 4, 8].map((o) => view.getFloat32(16 * i + o, true));
        const r = Math.hypot(x, y, z);
        check(r > 0 && r <= maxRange + 1e-3, `${channel.topic} ${n}: point ${i} at ${r} m`);
        check(view.getUint16(16 * i + 12, true) < manifest.meshes.length, `point ${i}'s mesh`);
        points += 1;
      }
    }
    if (channel.topic === "/tf" && n === 1) {
      const t = decoded.transforms[0];
      check(t.header.frame_id === "map" && t.child_frame_id === "base_link", "/tf map → base_link");
      near(seconds(t.header.stamp), sonar[0][0], 1e-6, "first /tf stamp");
    }
    if (channel.topic === "/ground_truth/pose" && n === 1) {
      const vehicle = tum("poses/vehicle.tum")[0];
      const p = decoded.pose.position;
      const q = decoded.pose.orientation;
      [p.x, p.y, p.z, q.x, q.y, q.z, q.w].forEach((v, i) => near(v, vehicle[i + 1], 1e-8, `true pose field ${i}`));
    }
  }
  for (const [topic, want] of Object.entries(expected)) {
    check((seen[topic] || 0) === want[1], `${topic}: read ${seen[topic]} messages`);
  }
  if (simulated) check(points > 0, "direct returns on /sonar/labels/points");
  await fd.close();
  console.log(`${bagPath}: ${Object.entries(seen).map(([t, n]) => `${t} ${n}`).join(", ")}; ` +
              `${failures} failures`);
  process.exit(failures === 0 ? 0 : 1);
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
