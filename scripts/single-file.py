#!/usr/bin/env python3
"""Writes dist/cutroute.html: the whole release build in one file that opens when
double-clicked (file://), where a page can fetch nothing beside it.

- the style sheets become <style> elements, the icon a data URL;
- the app's wasm-bindgen module and its wasm (base64) run from an inline module script;
- the solver worker's script and wasm become a loader script behind a Blob URL
  (`globalThis.cutrouteWorkerLoader`, spawned by src/worker_client.rs through src/embedded.rs);
- the bundled samples are carried as bytes (`globalThis.cutrouteFiles`, read by the app's
  fetch of `./assets/samples/…`);
- the service worker and the manifest are left out (browsers have none for file://).

Usage: scripts/single-file.py dist"""
import base64
import pathlib
import re
import sys

dist = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "dist")
page = (dist / "index.html").read_text(encoding="utf-8")


def b64(path: pathlib.Path) -> str:
    return base64.b64encode(path.read_bytes()).decode("ascii")


def script_safe(text: str, what: str) -> str:
    """Text that can stand inside a <script> element."""
    if re.search(r"</script", text, re.IGNORECASE):
        sys.exit(f"single-file: {what} contains </script")
    return text


def inline_css(match: re.Match) -> str:
    css = (dist / match.group(1)).read_text(encoding="utf-8")
    return f"<style>\n{css}\n</style>"


page, sheets = re.subn(r'<link rel="stylesheet" href="\./([^"]+\.css)"[^>]*/?>', inline_css, page)
if sheets == 0:
    sys.exit("single-file: no style sheet found in index.html")
page = page.replace('<link rel="icon" href="icon.svg" type="image/svg+xml" />',
                    f'<link rel="icon" href="data:image/svg+xml;base64,{b64(dist / "icon.svg")}" />')
page = re.sub(r'<link rel="manifest"[^>]*/?>', "", page)
page = re.sub(r'<link rel="(modulepreload|preload)"[^>]*>', "", page)
# The service worker's registration: it checks for http(s) itself, but has nothing to do here.
page = re.sub(r"<script>\s*// Offline after the first visit.*?</script>", "", page, flags=re.S)

# The app: Trunk's module script imports the bindings and fetches the wasm.
boot = re.search(r"<script type=\"module\">\s*import init, \* as bindings from '\./([^']+\.js)';\s*"
                 r"const wasm = await init\(\{ module_or_path: '\./([^']+\.wasm)' \}\);", page)
if not boot:
    sys.exit("single-file: Trunk's start-up script not found in index.html")
bindings = script_safe((dist / boot.group(1)).read_text(encoding="utf-8"), boot.group(1))
app_wasm = b64(dist / boot.group(2))
start = page.index("<script type=\"module\">", boot.start())
end = page.index("</script>", start) + len("</script>")

worker_js = script_safe((dist / "worker.js").read_text(encoding="utf-8"), "worker.js")
worker_wasm = b64(dist / "worker_bg.wasm")
samples = sorted((dist / "assets" / "samples").glob("*"))
# The lecture gallery's bundled list (src/gallery.rs) names the samples beside it.
carried_files = [(f"./assets/samples/{p.name}", p) for p in samples]
carried_files.append(("./assets/lectures.json", dist / "assets" / "lectures.json"))
files = ",\n".join(f'  "{url}": "{b64(p)}"' for url, p in carried_files)

carried = f"""<script id="cutroute-worker-js" type="text/plain">
{worker_js}
</script>
<script>
// What the single-file page carries (see src/embedded.rs).
(() => {{
  const bytes = (text) => Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  const files = {{
{files}
  }};
  globalThis.cutrouteFiles = Object.fromEntries(Object.entries(files).map(([k, v]) => [k, bytes(v)]));
  const workerWasm = "{worker_wasm}";
  const loader = document.getElementById('cutroute-worker-js').textContent
    + `\\nwasm_bindgen({{ module_or_path: Uint8Array.from(atob("${{workerWasm}}"), (c) => c.charCodeAt(0)) }});\\n`;
  globalThis.cutrouteWorkerLoader = URL.createObjectURL(new Blob([loader], {{ type: 'application/javascript' }}));
}})();
</script>
<script type="module">
{bindings}
const cutrouteAppWasm = await __wbg_init({{ module_or_path: Uint8Array.from(atob("{app_wasm}"), (c) => c.charCodeAt(0)) }});
dispatchEvent(new CustomEvent("TrunkApplicationStarted", {{detail: {{wasm: cutrouteAppWasm}}}}));
</script>"""
page = page[:start] + carried + page[end:]
out = dist / "cutroute.html"
out.write_text(page, encoding="utf-8")
print(f"[build] {out}: {out.stat().st_size} bytes, one file (double-click to open)", file=sys.stderr)
