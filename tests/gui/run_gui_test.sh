#!/usr/bin/env bash
# Runs one GUI test macro in the real FreeCAD under a virtual X server. The macro ends FreeCAD
# with os._exit(code); `timeout` turns a hang into a failure (exit 124) instead of a stuck CI.
set -u
macro=$1
export QTWEBENGINE_DISABLE_SANDBOX=1
exec timeout -k 10 300 xvfb-run -a -s "-screen 0 1280x1024x24" freecad "$macro"
