#!/usr/bin/perl
# A task that reports the signals it gets: probe.pl NAME LOG [stay|exit] [GRACE]
# Appends "TIME NAME@HOST pid=PID EVENT" lines to LOG: "start", "got SIG" for each catchable
# signal, "alive" every 0.25 s once signalled (the last one dates a SIGKILL). "stay" ignores
# every signal; "exit" exits 0 GRACE seconds after its first TERM or INT (a clean shutdown that
# takes GRACE seconds).
use strict;
use warnings;
use Time::HiRes qw(time sleep);
my ($name, $log, $mode, $grace) = @ARGV;
$mode //= 'stay';
$grace //= 0;
open(my $h, '<', '/proc/sys/kernel/hostname') or die;
my $host = <$h>;
chomp $host;
sub report {
  open(my $f, '>>', $log) or die;
  printf $f "%.3f %s@%s pid=%d %s\n", time, $name, $host, $$, "@_";
  close $f;
}
my ($stop, $signalled, $next) = (0, 0, 0);
for my $s (qw(TERM INT HUP USR1 USR2 CONT QUIT ALRM)) {
  $SIG{$s} = sub {
    report("got $s");
    $signalled = 1;
    $stop ||= time + $grace if $mode eq 'exit' && ($s eq 'TERM' || $s eq 'INT');
  };
}
report("start");
while (1) {
  sleep 0.05;
  if ($stop && time >= $stop) { report("exits 0"); exit 0; }
  if ($signalled && time >= $next) { report("alive"); $next = time + 0.25; }
}
