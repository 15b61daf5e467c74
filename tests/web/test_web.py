#!/usr/bin/python3
"""test_web.py — meshcorrd's web UI in a real browser (Debian's chromium,
headless, driven by chromedriver through python3-selenium), against a
daemon tests/unit/test_web.c started on loopback with jobs of two users.

Checks, each an assertion (exit status 1 and the reason on stderr):
a wrong token is refused and the login page says so; a good one logs in and
the job list shows the user's jobs and not the other user's; the running
job's page draws a plot that gains points while it runs (from the job's
server-sent events; the stream's events are checked, and its cap); the finished job's
page shows its quality, the picture of its map and its map links; another user's job page and its
API answer 404; every resource the pages load comes from the daemon (the
browser resolves no other host, and the Content-Security-Policy allows
nothing else); every GET of docs/openapi.yaml answers; the cancel button
cancels the running job.
Screenshots go to --shots (PNG)."""
import argparse
import http.client
import json
import os
import sys
import time
import urllib.error
import urllib.request

import yaml
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By


def fail(msg):
    print("test_web.py: FAIL: " + msg, file=sys.stderr)
    sys.exit(1)


def check(cond, msg):
    if not cond:
        fail(msg)


def wait_for(what, fn, timeout=30.0):
    t0 = time.time()
    while time.time() - t0 < timeout:
        try:
            v = fn()
            if v:
                return v
        except Exception:  # the page may be between two renders
            pass
        time.sleep(0.2)
    fail("timed out after %.0f s waiting for %s" % (timeout, what))


def api(base, path, token):
    req = urllib.request.Request(base + "/api/v1" + path, headers={"Authorization": "Bearer " + token})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"{}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", required=True)
    ap.add_argument("--token", required=True, help="the user's token")
    ap.add_argument("--wrong-token", required=True)
    ap.add_argument("--running", type=int, required=True, help="the user's running job")
    ap.add_argument("--done", type=int, required=True, help="the user's completed job")
    ap.add_argument("--other", type=int, required=True, help="another user's job")
    ap.add_argument("--shots", required=True, help="folder for the screenshots")
    a = ap.parse_args()
    os.makedirs(a.shots, exist_ok=True)
    base = a.url.rstrip("/")
    host = base.split("//")[1].split(":")[0]

    opts = webdriver.ChromeOptions()
    opts.binary_location = "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1280,900", "--no-first-run", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--disable-extensions",
                # no network beyond the daemon: every other host name fails to resolve
                "--host-resolver-rules=MAP * ~NOTFOUND , EXCLUDE " + host):
        opts.add_argument(arg)
    drv = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    drv.set_page_load_timeout(30)
    try:
        run(drv, a, base)
    finally:
        drv.quit()
    print("test_web.py: all checks passed")


def shot(drv, a, name):
    path = os.path.join(a.shots, name + ".png")
    drv.save_screenshot(path)
    print("screenshot " + path)


def own_resources_only(drv, base):
    urls = drv.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
    urls.append(drv.current_url)
    for u in urls:
        check(u.startswith(base + "/"), "the page loaded %s, not from the daemon" % u)
    return len(urls)


def run(drv, a, base):
    # a page without a session goes to the login page
    drv.get(base + "/")
    wait_for("the login page", lambda: drv.current_url == base + "/login")

    # a wrong token is refused
    drv.find_element(By.NAME, "token").send_keys(a.wrong_token)
    drv.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    msg = wait_for("the refusal", lambda: drv.find_element(By.ID, "msg").text)
    check("Unknown token" in msg, "a wrong token got %r" % msg)
    check(not drv.get_cookies(), "a wrong token got a cookie")
    shot(drv, a, "1-login-refused")

    # the right one logs in: the list shows the user's jobs, not the other's
    drv.find_element(By.NAME, "token").send_keys(a.token)
    drv.find_element(By.CSS_SELECTOR, "button[type=submit]").click()
    wait_for("the job list", lambda: drv.find_element(By.ID, "job-%d" % a.running))
    cookie = drv.get_cookie("mc_session")
    check(cookie and cookie["httpOnly"] and cookie.get("sameSite") == "Strict", "session cookie %r" % cookie)
    check(drv.find_element(By.ID, "job-%d" % a.done), "the completed job is not listed")
    wait_for("the running job's state", lambda: "RUNNING" in drv.find_element(By.ID, "job-%d" % a.running).text)
    check(not drv.find_elements(By.ID, "job-%d" % a.other), "another user's job is listed")
    rows = drv.find_elements(By.CSS_SELECTOR, "#jobs tbody tr")
    check(len(rows) == 2, "the list has %d rows, the user has 2 jobs" % len(rows))
    n = own_resources_only(drv, base)
    check(n >= 4, "the list page loaded %d resources (page, css, 2 scripts at least)" % n)
    shot(drv, a, "2-job-list")

    # the state filter
    drv.get(base + "/?state=COMPLETED")
    wait_for("the filtered list", lambda: drv.find_element(By.ID, "job-%d" % a.done))
    wait_for("the running job filtered out", lambda: not drv.find_elements(By.ID, "job-%d" % a.running))

    # the running job's plot gains points
    drv.get(base + "/jobs/%d" % a.running)
    plot = drv.find_element(By.ID, "plot")
    first = wait_for("the first points", lambda: int(plot.get_attribute("data-points")))
    wait_for("more points than %d" % first, lambda: int(plot.get_attribute("data-points")) > first, 60)
    # read in one script: the plot is redrawn as records arrive
    series = sorted(drv.execute_script(
        "return [...document.querySelectorAll('#plot polyline')].map(p => p.dataset.series)"))
    check("energy" in series and "beta" in series and "membrane" in series, "plot series %r" % series)
    check(drv.find_element(By.ID, "cancel").is_displayed(), "no cancel button on a running job of the owner")
    check(plot.get_attribute("data-live") == "events", "the plot is not following the event stream")
    own_resources_only(drv, base)
    shot(drv, a, "3-running-job")

    # the completed job: quality and maps
    drv.get(base + "/jobs/%d" % a.done)
    wait_for("the result section", lambda: drv.find_element(By.ID, "result").is_displayed())
    quality = wait_for("the quality", lambda: drv.find_element(By.ID, "quality").text)
    check("Verdict" in quality, "quality section: %r" % quality)
    href = drv.find_element(By.ID, "map-p").get_attribute("href")
    check(href.endswith("/api/v1/jobs/%d/maps/p" % a.done), "map link %r" % href)
    wait_for("the finished plot", lambda: int(drv.find_element(By.ID, "plot").get_attribute("data-points")) > 0)
    # the picture of the map: drawn by the server, then shown at its size
    img = drv.find_element(By.ID, "picture")
    wait_for("the map's picture", lambda: img.is_displayed() and drv.execute_script(
        "return arguments[0].complete && arguments[0].naturalWidth", img) >= 800, 60)
    drv.execute_script("arguments[0].scrollIntoView()", img)
    shot(drv, a, "4-completed-job")
    req = urllib.request.Request(href, headers={"Authorization": "Bearer " + a.token})
    with urllib.request.urlopen(req, timeout=10) as r:
        rows = r.read().decode().splitlines()
    check(len(rows) > 100 and len(rows[0].split()) == 4, "map P: %d rows, first %r" % (len(rows), rows[:1]))

    # another user's job: 404 on the page and the API
    drv.get(base + "/jobs/%d" % a.other)
    check("no such job" in drv.find_element(By.TAG_NAME, "body").text, "another user's job page shows something")
    status, body = api(base, "/jobs/%d" % a.other, a.token)
    check(status == 404, "another user's job: API answered %d %r" % (status, body))
    status, body = api(base, "/jobs/%d/history" % a.other, a.token)
    check(status == 404, "another user's history: API answered %d" % status)
    status, body = api(base, "/jobs", a.token)
    check(status == 200 and a.other not in [j["id"] for j in body["jobs"]], "another user's job in the API list")
    status, body = api(base, "/jobs", a.wrong_token)
    check(status == 401, "a wrong Bearer token: %d" % status)
    shot(drv, a, "5-other-users-job")

    # every GET of docs/openapi.yaml answers 200 for the user's completed job
    with open("docs/openapi.yaml") as f:
        spec = yaml.safe_load(f)
    for path, ops in spec["paths"].items():
        if "get" not in ops:
            continue
        url = path.replace("{id}", str(a.done)).replace("{map}", "p")
        req = urllib.request.Request(base + "/api/v1" + url, headers={"Authorization": "Bearer " + a.token})
        with urllib.request.urlopen(req, timeout=10) as r:
            check(r.status == 200, "GET %s: %d" % (url, r.status))

    # the workers page
    drv.get(base + "/workers")
    wait_for("the slots", lambda: len(drv.find_elements(By.CSS_SELECTOR, "#slots tbody tr")) >= 1)
    wait_for("the backend", lambda: "Backend local" in drv.find_element(By.ID, "summary").text)
    shot(drv, a, "6-workers")

    # the event stream: records as server-sent events, and a cap of 4 streams
    # per user (the fifth is refused)
    hostport = base.split("//")[1]
    streams = []
    for i in range(4):
        c = http.client.HTTPConnection(hostport, timeout=10)
        c.request("GET", "/api/v1/jobs/%d/events" % a.running, headers={"Authorization": "Bearer " + a.token})
        r = c.getresponse()
        check(r.status == 200 and r.getheader("Content-Type") == "text/event-stream",
              "stream %d: %d %s" % (i, r.status, r.getheader("Content-Type")))
        streams.append((c, r))
    first = b""
    while b"\n\n" not in first:
        first += streams[0][1].read1(4096)
    event = first.decode().split("\n\n")[0].split("\n")
    check(event[0].startswith("id: ") and event[1] == "event: progress" and event[2].startswith("data: {"),
          "first event %r" % event)
    check("energy" in json.loads(event[2][6:]), "event data %r" % event[2])
    status, body = api(base, "/jobs/%d/events" % a.running, a.token)
    check(status == 503 and "too many event streams" in body.get("error", ""), "a fifth stream: %d %r" % (status, body))
    for c, r in streams:
        c.close()
    time.sleep(6)  # the server notices the closed streams at their next write (a keepalive at most 5 s on)

    # cancel the running job from its page; a POST with the cookie alone (no
    # CSRF token) is refused
    drv.get(base + "/jobs/%d" % a.running)
    wait_for("the cancel button", lambda: drv.find_element(By.ID, "cancel").is_displayed())
    status = drv.execute_async_script(
        "const done = arguments[arguments.length - 1];"
        "fetch('/api/v1/jobs/%d/cancel', {method: 'POST'}).then(r => done(r.status), e => done(0));" % a.running)
    check(status == 403, "a cancel without the CSRF token got %r" % status)
    drv.find_element(By.ID, "cancel").click()
    wait_for("CANCELLED", lambda: "CANCELLED" in drv.find_element(By.ID, "facts").text, 30)
    shot(drv, a, "7-cancelled")
    status, body = api(base, "/jobs/%d" % a.running, a.token)
    check(status == 200 and body["state"] == "CANCELLED", "after cancel: %d %r" % (status, body))

    # logout ends the session
    drv.get(base + "/")
    wait_for("the list", lambda: drv.find_element(By.ID, "logout"))
    drv.find_element(By.ID, "logout").click()
    wait_for("the login page", lambda: drv.current_url == base + "/login")
    drv.get(base + "/")
    wait_for("the login page again", lambda: drv.current_url == base + "/login")


if __name__ == "__main__":
    main()
