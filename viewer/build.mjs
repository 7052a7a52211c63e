// Builds the report viewer into one minified IIFE inside the Python package, with the licence
// notices of everything bundled. Run by `make viewer` (npm ci && npm run build).
import { build } from 'esbuild';
import { readFileSync, writeFileSync, mkdirSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const out = join(here, '..', 'src', 'screwkit', 'report', 'static');
mkdirSync(out, { recursive: true });

await build({
  entryPoints: [join(here, 'src', 'main.js')],
  bundle: true,
  minify: true,
  format: 'iife',
  target: ['es2020'],
  legalComments: 'eof',
  outfile: join(out, 'screwkit-viewer.min.js'),
  logLevel: 'info',
});

const js = readFileSync(join(out, 'screwkit-viewer.min.js'), 'utf8');
if (/<\/script|<!--/i.test(js)) {
  throw new Error('the bundle contains "</script" or "<!--", which cannot be inlined in a page');
}

const bundled = [
  ['three', 'LICENSE'],
  ['chart.js', 'LICENSE.md'],
  ['@kurkle/color', 'LICENSE.md'],
];
const parts = ['Third-party software bundled in screwkit-viewer.min.js', ''];
for (const [pkg, file] of bundled) {
  const meta = JSON.parse(readFileSync(join(here, 'node_modules', pkg, 'package.json'), 'utf8'));
  parts.push(`== ${pkg} ${meta.version} (${meta.license}) ==`, '');
  parts.push(readFileSync(join(here, 'node_modules', pkg, file), 'utf8').trim(), '');
}
writeFileSync(join(out, 'THIRD_PARTY_LICENSES.txt'), parts.join('\n') + '\n');
console.log(`wrote ${join(out, 'screwkit-viewer.min.js')} (${js.length} bytes) and THIRD_PARTY_LICENSES.txt`);
