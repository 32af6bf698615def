// validate.mjs: runs the Khronos glTF validator (the version pinned in
// tests/node) over .glb/.gltf files.
//
//   node tests/validate.mjs file.glb...
//
// Prints one line per file with its error, warning, info and hint counts,
// then each error message. External URIs of a .gltf are resolved next to
// the file. Exits 1 if any file has errors or cannot be read, 2 on usage.
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const require = createRequire(import.meta.url);
const validator = require(path.join(here, 'node', 'node_modules', 'gltf-validator'));

async function validate(file) {
	const bytes = new Uint8Array(await readFile(file));
	return validator.validateBytes(bytes, {
		uri: path.basename(file),
		maxIssues: 1000,
		externalResourceFunction: async (uri) =>
			new Uint8Array(await readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)))),
	});
}

const files = process.argv.slice(2);
if (files.length === 0) {
	console.error('usage: node tests/validate.mjs file.glb...');
	process.exit(2);
}

let failed = false;
for (const file of files) {
	let report;
	try {
		report = await validate(file);
	} catch (e) {
		console.log(`${file}: cannot validate: ${e.message ?? e}`);
		failed = true;
		continue;
	}
	const i = report.issues;
	console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
	for (const m of i.messages) {
		if (m.severity === 0)
			console.log(`  error ${m.code}: ${m.message} (${m.pointer ?? 'document'})`);
	}
	if (i.numErrors > 0)
		failed = true;
}
process.exit(failed ? 1 : 0);
