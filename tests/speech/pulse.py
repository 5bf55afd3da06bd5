"""A private PulseAudio server with a null sink, so tests can "speak" into the default input.

Everything runs from a temporary directory with its own socket, so it never
touches a PulseAudio the machine may already run, and works as root. The
server and the `pacat` feeder are children of the test process and are
always terminated by `stop()`.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PACKAGES = "pulseaudio pulseaudio-utils libportaudio2 libasound2-plugins espeak-ng"


def missing_tools() -> list[str]:
    return [tool for tool in ("pulseaudio", "pactl", "pacat", "paplay", "espeak-ng") if shutil.which(tool) is None]


class VirtualMic:
    """`with VirtualMic() as mic: mic.play(wav)`; sounddevice's default input then hears the WAV."""

    def __init__(self, rescan: bool = True) -> None:
        # rescan=False leaves noticing the new server to the code under test.
        self.rescan = rescan
        self.folder = Path(tempfile.mkdtemp(prefix="nrtrans-pulse-"))
        self.socket = self.folder / "native"
        self.server: subprocess.Popen[bytes] | None = None
        self.feeder: subprocess.Popen[bytes] | None = None
        self._saved_env: dict[str, str | None] = {}

    def __enter__(self) -> VirtualMic:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def env(self) -> dict[str, str]:
        """What a client process needs to reach this server; set in os.environ while it runs."""
        return {"PULSE_SERVER": f"unix:{self.socket}", "PULSE_COOKIE": str(self.folder / "cookie")}

    def start(self) -> None:
        runtime = self.folder / "runtime"
        runtime.mkdir(mode=0o700)
        home = self.folder / "home"
        home.mkdir()
        for key, value in self.env().items():
            self._saved_env[key] = os.environ.get(key)
            os.environ[key] = value
        # The server's own files stay in the temporary folder; the test
        # process keeps its HOME and runtime directory.
        server_env = {**os.environ, "HOME": str(home), "XDG_RUNTIME_DIR": str(runtime),
                      "PULSE_RUNTIME_PATH": str(runtime / "pulse")}
        with (self.folder / "pulseaudio.log").open("wb") as log:
            self.server = subprocess.Popen(
                ["pulseaudio", "--daemonize=no", "--exit-idle-time=-1", "--use-pid-file=no", "-n",
                 "--disable-shm=yes", f"--load=module-native-protocol-unix auth-anonymous=1 socket={self.socket}",
                 "--load=module-null-sink sink_name=virt rate=16000 channels=1",
                 "--log-target=stderr"],
                stdout=log, stderr=log, env=server_env)
        deadline = time.monotonic() + 15
        while not self._ready():
            if self.server.poll() is not None or time.monotonic() > deadline:
                output = (self.folder / "pulseaudio.log").read_text(errors="replace")
                self.stop()
                raise RuntimeError(f"PulseAudio did not start:\n{output[-2000:]}")
            time.sleep(0.1)
        self._pactl("set-default-sink", "virt")
        self._pactl("set-default-source", "virt.monitor")
        # A null sink's monitor delivers no frames unless something plays.
        self.feeder = subprocess.Popen(["pacat", "--playback", "--device=virt", "--latency-msec=20",
                                        "/dev/zero"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if self.rescan:
            _rescan_portaudio()

    def play(self, wav: Path, timeout: float = 30.0) -> None:
        subprocess.run(["paplay", "--device=virt", str(wav)], check=True, timeout=timeout)

    def stop(self) -> None:
        for process in (self.feeder, self.server):
            if process is not None and process.poll() is None:
                process.terminate()
                try:
                    process.wait(5)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait(5)
        self.feeder = self.server = None
        for key, value in self._saved_env.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
        self._saved_env.clear()
        shutil.rmtree(self.folder, ignore_errors=True)
        if self.rescan:
            _rescan_portaudio()

    def _ready(self) -> bool:
        return subprocess.run(["pactl", "info"], capture_output=True, timeout=5).returncode == 0

    def _pactl(self, *args: str) -> None:
        subprocess.run(["pactl", *args], check=True, capture_output=True, timeout=5)


def _rescan_portaudio() -> None:
    """PortAudio lists devices once; make a test start from what exists now, not what an earlier test left."""
    sounddevice = sys.modules.get("sounddevice")
    if sounddevice is not None:
        sounddevice._terminate()
        sounddevice._initialize()


def speak(text: str, path: Path, voice: str = "ko", pad_s: float = 0.5, rate: int = 16000) -> Path:
    """espeak-ng into a 16 kHz WAV, with silence around it like a real utterance.

    Resampling here, the way `nrtrans transcribe` does, means PulseAudio
    plays the file as is and live capture hears what the file tests hear.
    """
    import wave

    import numpy as np

    from agent.speech.audio import read_wav, resample

    raw = path.with_suffix(".raw.wav")
    subprocess.run(["espeak-ng", "-v", voice, "-w", str(raw), text], check=True, timeout=30)
    audio = resample(read_wav(raw), rate)
    raw.unlink()
    pad = np.zeros(int(rate * pad_s), dtype=np.int16)
    with wave.open(str(path), "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(rate)
        out.writeframes(np.concatenate([pad, audio.samples, pad]).tobytes())
    return path
