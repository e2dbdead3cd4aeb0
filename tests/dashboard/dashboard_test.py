#!/usr/bin/env python3
"""The coordinator's web dashboard in a real headless Chromium (Debian's python3-selenium).

Starts tessera-server with one local worker and bearer tokens, opens the page, checks that the API
is refused visibly without the token, enters it, submits a scene bundle through the form's file
input, waits for the job to finish with its image shown, checks the workers table, cancels a
second job with its button, and checks the browser console holds no errors. Saves a screenshot.

Exit status: 0 passed, 1 failed, 77 skipped (selenium or Chromium missing; under CI=true that
fails instead).
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import tarfile
import time
import urllib.error
import urllib.request
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "support"))
from script_test import SKIP, Failure, run_in_temp_dir  # noqa: E402

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
SYSTEM_PYTHON = "/usr/bin/python3"  # Debian's selenium lives in its dist-packages
CLIENT_TOKEN = "dash-client-5c1e"
WORKER_TOKEN = "dash-worker-0b7a"
VIEWPORT = (1280, 900)
REPO = Path(__file__).resolve().parents[2]

try:
    from selenium import webdriver
    from selenium.common.exceptions import TimeoutException
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait
except ImportError:
    webdriver = None


def missing_tools():
    """What this test needs and does not find; re-executes under Debian's Python if that has selenium."""
    if webdriver is None and os.path.exists(SYSTEM_PYTHON) and os.path.realpath(sys.executable) != os.path.realpath(
            SYSTEM_PYTHON) and not os.environ.get("TESSERA_DASHBOARD_REEXEC"):
        os.environ["TESSERA_DASHBOARD_REEXEC"] = "1"  # once: a Python without selenium must not loop
        os.execv(SYSTEM_PYTHON, [SYSTEM_PYTHON] + sys.argv)
    missing = [] if webdriver is not None else ["python3-selenium"]
    missing += [p for p in (CHROMIUM, CHROMEDRIVER) if not os.access(p, os.X_OK)]
    return missing


def check(condition, message):
    if not condition:
        raise Failure(message)


# ---- the scene bundle -----------------------------------------------------------------------

def scene_files(scene_xml):
    """The XML and every file it references (meshes, textures, includes), relative to its folder."""
    root_dir = scene_xml.parent
    files = [scene_xml.name]
    for node in ET.parse(scene_xml).iter():
        ref = node.get("value") if node.tag == "string" and node.get("name") == "filename" else None
        ref = node.get("filename") if node.tag == "include" else ref
        if ref and "$" not in ref and (root_dir / ref).is_file():
            rel = os.path.relpath(root_dir / ref, root_dir)
            check(not rel.startswith(".."), f"{scene_xml} references {ref} outside its folder")
            files.append(rel)
    return sorted(set(files), key=files.index)


def make_bundle(scene_xml, out):
    with tarfile.open(out, "w") as tar:
        for rel in scene_files(scene_xml):
            tar.add(scene_xml.parent / rel, arcname=rel)
    return out


# ---- the coordinator ------------------------------------------------------------------------

class Server:
    def __init__(self, binary, worker, tmp):
        self.port_file = tmp / "port"
        self.log_path = tmp / "server.log"
        args = [binary, "--listen", "127.0.0.1:0", "--port-file", str(self.port_file), "--data-dir", str(tmp / "data"),
                "--local-workers", "1", "--client-token", CLIENT_TOKEN, "--worker-token", WORKER_TOKEN]
        if worker:
            args += ["--worker-binary", worker]
        self.log = open(self.log_path, "wb")
        # Its own process group: the local worker it forks goes down with it.
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT, start_new_session=True)
        self.url = None

    def wait_ready(self, seconds=30):
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            check(self.proc.poll() is None, f"tessera-server exited with {self.proc.returncode}")
            if self.url is None and self.port_file.exists():
                text = self.port_file.read_text().strip()
                if text:
                    self.url = f"http://127.0.0.1:{int(text)}"
            if self.url:
                try:
                    if self.request("/healthz", token=None)[0] == 200:
                        return
                except OSError:
                    pass
            time.sleep(0.05)
        raise Failure("tessera-server did not answer /healthz")

    def request(self, path, token=CLIENT_TOKEN, method="GET"):
        req = urllib.request.Request(self.url + path, method=method)
        if token:
            req.add_header("Authorization", f"Bearer {token}")
        try:
            with urllib.request.urlopen(req, timeout=10) as res:
                return res.status, res.read(), res.headers
        except urllib.error.HTTPError as e:
            return e.code, e.read(), e.headers

    def job(self, job_id):
        status, body, _ = self.request(f"/api/v1/jobs/{job_id}")
        check(status == 200, f"GET /api/v1/jobs/{job_id}: {status} {body[:200]!r}")
        return json.loads(body)

    def stop(self):
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGTERM)
                self.proc.wait(timeout=20)
            except (subprocess.TimeoutExpired, ProcessLookupError):
                pass
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)  # whatever of the group is left
        except ProcessLookupError:
            pass
        self.proc.wait()
        self.log.close()

    def log_tail(self, lines=40):
        try:
            return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])
        except OSError:
            return "(no log)"


# ---- the browser ----------------------------------------------------------------------------

def start_browser():
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu", "--hide-scrollbars",
                 f"--window-size={VIEWPORT[0]},{VIEWPORT[1]}", "--no-first-run", "--disable-extensions"):
        options.add_argument(flag)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=options)
    # The window size includes the (invisible) browser frame; the page itself gets exactly this.
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": VIEWPORT[0], "height": VIEWPORT[1], "deviceScaleFactor": 1, "mobile": False})
    return driver


def severe(entries):
    return [e for e in entries if e.get("level") == "SEVERE"]


def wait_for(driver, seconds, what, predicate):
    try:
        return WebDriverWait(driver, seconds, poll_frequency=0.2).until(lambda d: predicate(d))
    except TimeoutException:
        raise Failure(f"timed out after {seconds} s waiting for {what}") from None


JOB_ROW_JS = """
const row = document.querySelector(`#jobs tr[data-job-id="${arguments[0]}"]`);
if (!row) return null;
const img = document.getElementById('preview');
return {state: row.dataset.state, pct: row.querySelector('.pct')?.textContent,
        cancel_visible: !row.querySelector('.cancel').hidden,
        img: {job: img.dataset.jobId, complete: img.dataset.complete, w: img.naturalWidth, h: img.naturalHeight,
              loaded: img.complete}};
"""


def job_row(driver, job_id):
    return driver.execute_script(JOB_ROW_JS, str(job_id))


# The form's choices by element id: (text boxes, selects by value, checkboxes). A job's fields left
# out are reset to the form's defaults, so each submission says only what it sets.
FORM_BOXES = ("priority", "seed", "target-error")
FORM_SELECTS = ("integrator", "light-selection", "guiding", "denoise-mode")
FORM_CHECKS = ("adaptive", "denoise")


def fill_form(driver, choices):
    for field in FORM_BOXES:
        driver.find_element(By.ID, field).clear()
        if field in choices:
            driver.find_element(By.ID, field).send_keys(str(choices[field]))
    for field in FORM_SELECTS:
        Select(driver.find_element(By.ID, field)).select_by_value(choices.get(field, ""))
    for field in FORM_CHECKS:
        if driver.find_element(By.ID, field).is_selected() != bool(choices.get(field)):
            driver.find_element(By.ID, field).click()


def submit(driver, bundle, name, width, height, spp, **choices):
    previous = driver.find_element(By.ID, "submit-result").get_attribute("data-job-id")
    for field, value in (("job-name", name), ("width", width), ("height", height), ("spp", spp)):
        box = driver.find_element(By.ID, field)
        box.clear()
        box.send_keys(str(value))
    fill_form(driver, {k.replace("_", "-"): v for k, v in choices.items()})
    driver.find_element(By.ID, "bundle").send_keys(str(bundle))
    driver.find_element(By.ID, "submit-button").click()

    def submitted(d):
        result = d.find_element(By.ID, "submit-result")
        check("error-text" not in result.get_attribute("class"), f"the submission was refused: {result.text}")
        job_id = result.get_attribute("data-job-id")
        return int(job_id) if job_id and job_id != previous else None

    return wait_for(driver, 60, f"job '{name}' to be accepted", submitted)


def run(args, tmp):
    scene = Path(args.scene).resolve()
    bundle = make_bundle(scene, tmp / f"{scene.parent.name}.tar")
    print(f"bundle {bundle.name}: {', '.join(scene_files(scene))}")

    server = Server(args.server, args.worker, tmp)
    driver = None
    try:
        server.wait_ready()
        # Over plain HTTP first: the page is open, the API is not.
        status, page, headers = server.request("/", token=None)
        check(status == 200 and b"<title>Tessera farm</title>" in page, f"GET / without a token: {status}")
        check(headers.get("Cache-Control") == "no-cache", f"GET / Cache-Control: {headers.get('Cache-Control')}")
        for asset, ctype in (("/ui/app.js", "text/javascript"), ("/ui/style.css", "text/css")):
            status, _, headers = server.request(asset, token=None)
            check(status == 200 and headers.get("Content-Type", "").startswith(ctype), f"GET {asset}: {status}")
        check(server.request("/api/v1/jobs", token=None)[0] == 401, "the API answers without a token")

        driver = start_browser()
        driver.get(server.url + "/")
        check(driver.title == "Tessera farm", f"page title {driver.title!r}")

        # No token: the refusal is on the page, not only in the network log.
        banner = wait_for(driver, 20, "the 401 banner",
                          lambda d: d.find_element(By.ID, "banner") if d.find_element(By.ID, "banner").is_displayed()
                          else None)
        check("401" in banner.text and "token" in banner.text, f"banner says {banner.text!r}")
        print(f"without a token the page says: {banner.text}")
        # The refused fetches are logged as network errors; nothing else may be.
        for entry in severe(driver.get_log("browser")):
            check(entry.get("source") == "network" and "401" in entry.get("message", ""),
                  f"console error before the token: {entry}")

        token = driver.find_element(By.ID, "token")
        token.send_keys(CLIENT_TOKEN)
        driver.find_element(By.CSS_SELECTOR, "#token-form button[type=submit]").click()
        wait_for(driver, 20, "the banner to go", lambda d: not d.find_element(By.ID, "banner").is_displayed())
        # The page kept polling until the token was in: those refusals may be logged only now. Drain
        # them here, so the final check sees only what happened with the token.
        for entry in severe(driver.get_log("browser")):
            check(entry.get("source") == "network" and "401" in entry.get("message", ""),
                  f"console error while entering the token: {entry}")
        check(driver.execute_script("return sessionStorage.getItem('tessera.client_token')") == CLIENT_TOKEN,
              "the token is not in sessionStorage")

        # The local worker, as the workers table shows it.
        worker = wait_for(driver, 30, "the local worker in the workers table", lambda d: next(
            (r for r in d.find_elements(By.CSS_SELECTOR, "#workers tbody tr")
             if "local-0" in r.text and r.get_attribute("data-state") in ("idle", "busy")), None))
        print(f"workers table: {worker.text}")

        # A job through the form, watched to the end.
        job_id = submit(driver, bundle, "dashboard-demo", args.width, args.height, args.spp)
        print(f"submitted job #{job_id} ({args.width}x{args.height}, {args.spp} spp)")
        seen_partial = False

        def finished(d):
            nonlocal seen_partial
            row = job_row(d, job_id)
            if not row:
                return None
            check(row["state"] not in ("failed", "cancelled"), f"job #{job_id} ended {row['state']}")
            img = row["img"]
            seen_partial |= img["job"] == str(job_id) and img["complete"] == "false" and img["w"] > 0
            done = row["state"] == "done" and row["pct"] == "100%"
            shown = img["job"] == str(job_id) and img["complete"] == "true" and img["loaded"] and img["w"] > 0
            return row if done and shown else None

        t0 = time.monotonic()
        row = wait_for(driver, args.timeout, f"job #{job_id} to finish with its image shown", finished)
        print(f"job #{job_id} done in {time.monotonic() - t0:.1f} s; image {row['img']['w']}x{row['img']['h']}"
              f"{', partial images shown while it rendered' if seen_partial else ''}")
        status = server.job(job_id)
        check(status["state"] == "done" and status["progress"] == 1, f"the API says {status['state']}")
        check((row["img"]["w"], row["img"]["h"]) == (status["width"], status["height"]),
              f"image {row['img']['w']}x{row['img']['h']} for a {status['width']}x{status['height']} job")
        facts = driver.find_element(By.ID, "detail-facts").text
        check("done" in facts and "100%" in facts, f"the details say {facts!r}")

        # The worker's speed is known once it has rendered something.
        wait_for(driver, 20, "the worker's speed", lambda d: any(
            "samples/s" in r.text for r in d.find_elements(By.CSS_SELECTOR, "#workers tbody tr")))
        # And the memory its loaded scene takes, from its heartbeats.
        wait_for(driver, 20, "the worker's scene memory", lambda d: any(
            "KiB" in r.text or "MiB" in r.text for r in d.find_elements(By.CSS_SELECTOR, "#workers tbody tr")))
        driver.execute_script("window.scrollTo(0, 0)")
        Path(args.screenshot).parent.mkdir(parents=True, exist_ok=True)
        check(driver.save_screenshot(args.screenshot), "the screenshot was not saved")
        print(f"screenshot: {args.screenshot}")

        # A second job, cancelled with its button (far too many samples to end by itself).
        long_id = submit(driver, bundle, "to-cancel", args.width, args.height, 1 << 16)
        button = wait_for(driver, 30, f"job #{long_id}'s cancel button", lambda d: next(
            (b for b in d.find_elements(By.CSS_SELECTOR, f'#jobs tr[data-job-id="{long_id}"] button.cancel')
             if b.is_displayed()), None))
        button.click()
        wait_for(driver, 30, f"job #{long_id} to show cancelled",
                 lambda d: (job_row(d, long_id) or {}).get("state") == "cancelled")
        check(server.job(long_id)["state"] == "cancelled", "the API does not say cancelled")
        check(not job_row(driver, long_id)["cancel_visible"], "a cancelled job still has a cancel button")
        print(f"job #{long_id} cancelled from the page")

        # A denoised job with every other choice of the form set too: the job gets each as its field.
        # Once done, the toggle shows its denoised image.
        chosen = {"integrator": "path", "light_selection": "power", "guiding": "off", "adaptive": True,
                  "denoise": True, "denoise_mode": "preview", "seed": 7, "priority": 3, "target_error": 0.5}
        dn_id = submit(driver, bundle, "denoised", args.width, args.height, args.spp, **chosen)
        settings = server.job(dn_id)["settings"]
        expected = dict(chosen, guiding=False)
        wrong = {k: (settings.get(k), v) for k, v in expected.items() if settings.get(k) != v}
        check(not wrong, f"the form's choices did not reach the job (got, chose): {wrong}")
        print(f"job #{dn_id} has the form's settings: {expected}")
        wait_for(driver, args.timeout, f"job #{dn_id} to finish",
                 lambda d: (job_row(d, dn_id) or {}).get("state") == "done")
        check(server.job(dn_id)["denoise_state"] == "done", f"the API says {server.job(dn_id)['denoise_state']}")
        wait_for(driver, 20, "the raw/denoised toggle", lambda d: d.find_element(By.ID, "image-choice").is_displayed())
        driver.find_element(By.CSS_SELECTOR, 'input[name="image-kind"][value="denoised"]').click()
        shown = wait_for(driver, 60, f"job #{dn_id}'s denoised image", lambda d: d.execute_script(
            "const i = document.getElementById('preview');"
            "return i.dataset.jobId === arguments[0] && i.dataset.kind === 'denoised' && i.complete && "
            "i.naturalWidth > 0 ? [i.naturalWidth, i.naturalHeight] : null;", str(dn_id)))
        check(tuple(shown) == (args.width, args.height), f"denoised image {shown}")
        print(f"job #{dn_id} shown denoised ({shown[0]}x{shown[1]})")

        errors = severe(driver.get_log("browser"))
        check(not errors, "console errors: " + "; ".join(e.get("message", "") for e in errors))
        print("no console errors")
    except Exception:
        print(f"--- server log (tail) ---\n{server.log_tail()}", file=sys.stderr)
        raise
    finally:
        if driver is not None:
            driver.quit()
        server.stop()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", required=True, help="the tessera-server binary")
    parser.add_argument("--worker", help="the tessera-worker binary (default: beside the server)")
    parser.add_argument("--screenshot", required=True, help="where to save the PNG screenshot")
    parser.add_argument("--scene", default=str(REPO / "scenes" / "demo" / "scene.xml"))
    parser.add_argument("--width", type=int, default=360)
    parser.add_argument("--height", type=int, default=240)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--timeout", type=float, default=120, help="seconds the job may take")
    args = parser.parse_args()

    missing = missing_tools()
    if missing:
        if os.environ.get("CI") == "true":
            print(f"FAIL: missing {', '.join(missing)} (scripts/install-deps.sh installs them)")
            return 1
        print(f"SKIP: missing {', '.join(missing)} (scripts/install-deps.sh installs them)")
        return SKIP
    for path in (args.server, args.scene):
        if not os.path.exists(path):
            print(f"FAIL: {path} does not exist")
            return 1

    return run_in_temp_dir("tessera-dashboard-", run, args)


if __name__ == "__main__":
    sys.exit(main())
