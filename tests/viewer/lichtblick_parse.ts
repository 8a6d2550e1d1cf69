// Lichtblick's own MCAP parsing code (packages/mcap-support) over every channel and message.
import { readFileSync } from "fs";
import { McapIndexedReader } from "@mcap/core";
import { loadDecompressHandlers, parseChannel } from "./src";

class Readable {
  constructor(private buf: Uint8Array) {}
  async size() { return BigInt(this.buf.byteLength); }
  async read(offset: bigint, size: bigint) {
    return this.buf.subarray(Number(offset), Number(offset + size));
  }
}

async function main() {
  const decompressHandlers = await loadDecompressHandlers();
  for (const path of process.argv.slice(2)) {
    const reader = await McapIndexedReader.Initialize({
      readable: new Readable(new Uint8Array(readFileSync(path))),
      decompressHandlers,
    });
    const parsed = new Map<number, ReturnType<typeof parseChannel> | Error>();
    for (const [id, ch] of reader.channelsById) {
      const schema = reader.schemasById.get(ch.schemaId);
      try {
        parsed.set(id, parseChannel({ messageEncoding: ch.messageEncoding, schema }));
      } catch (e) {
        parsed.set(id, e as Error);
      }
    }
    let ok = 0, bad = 0, total = 0;
    const problems = new Map<string, string>();
    let roll: unknown = undefined;
    for await (const msg of reader.readMessages()) {
      total++;
      const ch = reader.channelsById.get(msg.channelId)!;
      const p = parsed.get(msg.channelId)!;
      if (p instanceof Error) { bad++; problems.set(ch.topic, p.message); continue; }
      try {
        const value = p.deserialize(msg.data) as Record<string, unknown>;
        if (ch.topic === "/mavlink/in/ATTITUDE" && roll === undefined) roll = value.roll;
        ok++;
      } catch (e) { bad++; problems.set(ch.topic, (e as Error).message); }
    }
    const channels = reader.channelsById.size;
    const badChannels = [...parsed.values()].filter((p) => p instanceof Error).length;
    console.log(JSON.stringify({ path, channels, channelsParsed: channels - badChannels, total, ok, bad,
      attitudeRoll: roll, problems: Object.fromEntries(problems) }));
  }
}
main().catch((e) => { console.error(e); process.exit(1); });
