#!/bin/sh
# A participant from before `check` existed: it knows only `run`.
case "$1" in run) exit 0 ;; *) echo "unknown command $1" >&2; exit 2 ;; esac
