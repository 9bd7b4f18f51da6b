% The command-line launcher of the Octave peer, a client of the job-file protocol of
% BENCHMARK.md section 5:
%
%     octave-cli --norc --quiet --no-history bench/peers/octave_rotor_cli.m JOB.json
%
% runs octave_rotor(JOB.json) (next to this file) and prints its one JSON line,
% {"solve_seconds": S, "version": ..., "method": "ode45"}, S being tic/toc around the
% integration alone (Octave's start-up, reading the job and writing the files excluded).
% Exit status 2 on a bad job (the message names the field and its value), 1 when the
% integration fails. (--no-history: Octave 7 otherwise reports an error at exit when it
% cannot save its history, as under a read-only or missing HOME.)
args = argv();
if numel(args) ~= 1
  fprintf(2, 'usage: octave-cli octave_rotor_cli.m JOB.json\n');
  exit(2);
end
addpath(fileparts(mfilename('fullpath')));
try
  info = octave_rotor(args{1});
catch err
  fprintf(2, '%s\n', err.message);
  if strncmp(err.identifier, 'rotor:job', 9)
    exit(2);
  end
  exit(1);
end
printf('{"solve_seconds": %.17g, "version": "%s", "method": "%s"}\n', ...
       info.solve_seconds, info.version, info.method);
exit(0);
