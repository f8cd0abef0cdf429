#!/usr/bin/python3
"""Evaluates a JavaScript expression in a page opened by headless Chromium and prints its value as JSON.

    chromium_eval.py URL (EXPRESSION | --script FILE) [--timeout SECONDS]

The expression may return a promise; its settled value is printed. This talks the Chrome DevTools
Protocol over --remote-debugging-pipe (JSON messages separated by NUL bytes on file descriptors 3
and 4), so it can wait for work a page does after its load event, such as decoding a whole video,
which `chromium --dump-dom` does not wait for. Exit status: 0 with the value on stdout; 1 when the
expression throws, the page does not load or the time runs out (the reason on stderr).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading


class Browser:
    def __init__(self, profile):
        to_chrome_r, self.to_chrome = os.pipe()
        self.from_chrome, from_chrome_w = os.pipe()
        # Chromium reads commands on fd 3 and writes replies and events on fd 4.
        def child_fds():
            # Via fresh descriptors, so that neither end is already 3 or 4 (dup2 onto itself would
            # keep it close-on-exec) nor overwritten by the other.
            read_end, write_end = os.dup(to_chrome_r), os.dup(from_chrome_w)
            os.dup2(read_end, 3)
            os.dup2(write_end, 4)
        self.process = subprocess.Popen(
            ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--remote-debugging-pipe",
             "--autoplay-policy=no-user-gesture-required", "--mute-audio", f"--user-data-dir={profile}"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            preexec_fn=child_fds, close_fds=False)
        os.close(to_chrome_r)
        os.close(from_chrome_w)
        self.buffer = b""
        self.next_id = 0
        self.events = []

    def _read_message(self):
        while b"\0" not in self.buffer:
            chunk = os.read(self.from_chrome, 65536)
            if not chunk:
                raise RuntimeError("Chromium closed the DevTools pipe")
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def send(self, method, params=None, session=None):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.to_chrome, json.dumps(message).encode() + b"\0")
        while True:
            reply = self._read_message()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error'].get('message')}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_event(self, method):
        while True:
            for k, event in enumerate(self.events):
                if event.get("method") == method:
                    return self.events.pop(k)
            self.events.append(self._read_message())

    def close(self):
        try:
            self.send("Browser.close")
        except Exception:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("url")
    parser.add_argument("expression", nargs="?")
    parser.add_argument("--script", help="a file holding the expression")
    parser.add_argument("--timeout", type=float, default=120)
    args = parser.parse_args()
    if (args.expression is None) == (args.script is None):
        parser.error("give either EXPRESSION or --script FILE")
    expression = args.expression if args.script is None else open(args.script, encoding="utf-8").read()
    with tempfile.TemporaryDirectory(prefix="chromium_eval_") as profile:
        browser = Browser(profile)
        # A watchdog: a page that never settles ends the browser, which ends the reads above.
        timer = threading.Timer(args.timeout, browser.process.kill)
        timer.start()
        try:
            target = browser.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            session = browser.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
            browser.send("Page.enable", session=session)
            navigated = browser.send("Page.navigate", {"url": args.url}, session=session)
            if navigated.get("errorText"):
                raise RuntimeError(f"{args.url}: {navigated['errorText']}")
            browser.wait_event("Page.loadEventFired")
            result = browser.send("Runtime.evaluate", {"expression": expression, "awaitPromise": True, "returnByValue": True},
                                  session=session)
            if "exceptionDetails" in result:
                details = result["exceptionDetails"]
                raise RuntimeError(details.get("exception", {}).get("description") or details.get("text"))
            print(json.dumps(result["result"].get("value")))
        except Exception as error:
            reason = "timed out" if not timer.is_alive() else str(error)
            print(f"chromium_eval: {reason}", file=sys.stderr)
            return 1
        finally:
            timer.cancel()
            browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
