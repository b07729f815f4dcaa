// node validate_foxglove.mjs DUMP...: each DUMP is mcap_channel_dump's output for one channel. Its
// messages are validated against Foxglove's published JSON schema of the channel's schema name
// (npm @foxglove/schemas), when Foxglove has one, and against the schema written in the MCAP file;
// a CompressedImage's data must be base64 of a JPEG. Prints a line per channel; exit 1 on any error.
import { readFileSync } from "node:fs";
import Ajv from "ajv";
import * as foxglove from "@foxglove/schemas/jsonschema.js";

const ajv = new Ajv({ strict: false, allErrors: true });
let failed = false;
for (const path of process.argv.slice(2)) {
  const lines = readFileSync(path, "utf8").split("\n").filter((line) => line.length > 0);
  const [name, schemaEncoding, messageEncoding, count] = lines[0].split(" ");
  const messages = lines.slice(2).map((line) => JSON.parse(line));
  const problems = [];
  if (schemaEncoding !== "jsonschema" || messageEncoding !== "json") problems.push(`encodings ${schemaEncoding}/${messageEncoding}`);
  if (messages.length !== Number(count) || messages.length === 0) problems.push(`${messages.length} messages of ${count}`);
  const validators = [["the file's schema", ajv.compile(JSON.parse(lines[1]))]];
  const published = name.startsWith("foxglove.") ? foxglove[name.slice("foxglove.".length)] : undefined;
  if (name.startsWith("foxglove.") && !published) problems.push(`Foxglove publishes no schema ${name}`);
  if (published) validators.push([`Foxglove's ${name}`, ajv.compile(published)]);
  messages.forEach((message, index) => {
    for (const [which, validate] of validators) {
      if (!validate(message)) problems.push(`message ${index} against ${which}: ${ajv.errorsText(validate.errors)}`);
    }
    if (name === "foxglove.CompressedImage") {
      const jpeg = Buffer.from(message.data, "base64");
      if (jpeg[0] !== 0xff || jpeg[1] !== 0xd8 || message.format !== "jpeg") problems.push(`message ${index}: data is no JPEG`);
    }
  });
  console.log(`${path}: ${name}, ${messages.length} messages, checked against ${validators.map(([which]) => which).join(" and ")}: ` +
              (problems.length ? `${problems.length} problem(s)` : "valid"));
  for (const problem of problems.slice(0, 5)) console.log(`  ${problem}`);
  failed ||= problems.length > 0;
}
process.exit(failed ? 1 : 0);
