function info = octave_rotor(job_path)
%OCTAVE_ROTOR  The rotorbench rotor with ode45 and event functions: a peer client.
%
%   info = octave_rotor('job.json') reads a job file of the benchmark's protocol
%   (BENCHMARK.md section 5), integrates the scene, writes the trace and events files the
%   job names, and returns struct('solve_seconds', S, 'version', V, 'method', 'ode45').
%   octave_rotor_cli.m is the command-line launcher `rotor bench` starts.
%
%   What a MATLAB user of the source writes for the two-disc rotor with set-valued
%   friction (docs/model.md): state x = [alpha; omega_u; omega_l],
%
%       alpha'        = omega_u - omega_l
%       J_u omega_u'  = k_m u - k_theta alpha - T_fu(omega_u)
%       J_l omega_l'  =         k_theta alpha - T_fl(omega_l)
%
%   integrated by ode45 (RelTol = AbsTol = the job's tol) piece by piece, restarted at
%   every mode switch located by an event function (odeset('Events', ...)):
%
%   * each disc with a switching surface is in a mode: slip on branch s = +1 / -1 (the
%     sign of its omega) or stick (s = 0). The lower disc always has one; the upper disc
%     has one when its law is set-valued or kinked (T_su, dT_su or db_u nonzero: the
%     Stribeck set), else it is integrated straight through omega_u = 0 (Table 1);
%   * slip on branch s: the friction law of that branch, continued smoothly past
%     omega = 0 (upper: T_fu = dT_su + s db_u omega + b_u omega + s T_su; lower:
%     T_fl = b_l omega + s N(s omega), N the level of docs/model.md written with tanh so
%     that it is smooth and odd); terminal event omega = 0 crossed in direction -s;
%   * at omega = 0 the disc sticks when its applied torque T_ex (k_theta alpha on the
%     lower disc, k_m u - k_theta alpha on the upper) lies in its stick interval
%     [lo, hi] = a(0) + N(0) [-1, 1], else it slips the way the torque pushes (a
%     reversal);
%   * stick: omega = 0, omega' = 0 (the friction takes the applied torque); terminal
%     events T_ex = hi (exit to s = +1) and T_ex = lo (exit to s = -1). The discs couple
%     only through alpha, so each disc's mode is decided alone.
%
%   Two things of GNU Octave 7's ode45 shape the loop below (MATLAB's ode45 needs
%   neither; this file keeps to functions MATLAB also has). Its event function is
%   evaluated at the output times only, and the event placed by linear interpolation
%   between two of them: the output times are the job's grid (0.01 s apart), so the
%   event's time and state would carry an error of order dt^2 times the curvature (about
%   3 digits, whatever the tolerance). Each event is therefore located again between the
%   two output times that bracket it (refine, below), to the tolerance. And a sign change
%   in the first output interval of a run is never terminal: every segment starts with an
%   output 1e-9 s after its start, which is not written to the trace, and after every
%   switch the other disc's mode is checked against the state, so that two switches at
%   one instant are both taken.

  job = read_job(job_path);
  m = rotor(job.params, job.u);
  grid = grid_times(job.dt, job.t_end);
  tic_id = tic;
  [y, events, nseg] = simulate(m, job.x0(:), grid, job.tol);
  seconds = toc(tic_id);
  write_trace(job.trace, grid, y);
  write_events(job.events, events);
  info = struct('solve_seconds', seconds, 'version', version(), ...
                'method', 'ode45', 'segments', nseg);
end

function job = read_job(path)
% The job as a struct; an error 'rotor:job:...' naming the field and the value otherwise.
  text = fileread(path);
  try
    job = jsondecode(text);
  catch err
    error('rotor:job:json', '%s: not a JSON job file: %s', path, err.message);
  end
  keys = {'params', 'u', 'x0', 't_end', 'dt', 'tol', 'trace', 'events'};
  for k = 1:numel(keys)
    if ~isfield(job, keys{k})
      error('rotor:job:missing', '%s: the job has no ''%s''', path, keys{k});
    end
  end
  for key = {'t_end', 'dt'}
    v = job.(key{1});
    if ~(isnumeric(v) && isscalar(v) && isfinite(v) && v > 0)
      error('rotor:job:value', '%s: %s = %s must be positive', path, key{1}, shown(v));
    end
  end
  if ~(isnumeric(job.tol) && isscalar(job.tol) && isfinite(job.tol) && job.tol > 0)
    error('rotor:job:value', ...
          '%s: tol = %s must be positive (this client has a tolerance)', ...
          path, shown(job.tol));
  end
  if ~(isnumeric(job.u) && isscalar(job.u) && isfinite(job.u))
    error('rotor:job:value', '%s: u = %s must be a finite number', path, shown(job.u));
  end
  if ~(isnumeric(job.x0) && numel(job.x0) == 3 && all(isfinite(job.x0)))
    error('rotor:job:value', '%s: x0 = %s must be 3 finite numbers', path, shown(job.x0));
  end
end

function s = shown(v)
% A value as the job shows it (null for an empty one).
  if isempty(v)
    s = 'null';
  elseif ischar(v)
    s = ['"' v '"'];
  elseif isnumeric(v)
    s = mat2str(v(:).', 17);
  else
    s = class(v);
  end
end

function m = rotor(p, u)
% The parameters as a struct of the numbers the fields and events need.
  need = {'j_u', 'k_m', 'k_theta', 'j_l', 'upper', 'lower'};
  for k = 1:numel(need)
    if ~isfield(p, need{k})
      error('rotor:job:params', 'params has no ''%s''', need{k});
    end
  end
  up = p.upper;
  lo = p.lower;
  m.j_u = p.j_u;
  m.j_l = p.j_l;
  m.k = p.k_theta;
  m.drive = p.k_m * u;
  m.b_u = up.b;
  m.t_su = field_or(up, 't_s', 0);
  m.dt_su = field_or(up, 'dt_s', 0);
  m.db_u = field_or(up, 'db', 0);
  if m.t_su < 0 || abs(m.dt_su) > m.t_su
    error('rotor:job:params', ...
          'upper.t_s = %.17g, upper.dt_s = %.17g: need |dt_s| <= t_s', m.t_su, m.dt_su);
  end
  % A smooth upper disc (Table 1) has no switching surface.
  m.upper_smooth = m.t_su == 0 && m.dt_su == 0 && m.db_u == 0;
  m.b_l = lo.b;
  m.t_sl = lo.t_s;
  if ~(m.t_sl > 0)
    error('rotor:job:params', ...
          'lower.t_s = %.17g: the lower disc must have static friction', m.t_sl);
  end
  switch lo.family
    case 'exponential'
      m.stribeck = false;
      m.t_1 = lo.t_1;  m.t_2 = lo.t_2;
      m.h_1 = lo.w_1 / 2;  m.h_2 = lo.w_2 / 2;   % tanh(w x / 2) = 1 - 2/(1 + e^(w x))
    case 'stribeck'
      m.stribeck = true;
      m.t_cl = lo.t_c;
      m.omega_s = lo.omega_s;
      m.delta = lo.delta;
    otherwise
      error('rotor:job:params', 'lower.family = "%s": expected exponential or stribeck', ...
            lo.family);
  end
  % Stick intervals [lo, hi], row 1 the upper disc, row 2 the lower.
  m.interval = [m.dt_su - m.t_su, m.dt_su + m.t_su; -m.t_sl, m.t_sl];
end

function v = field_or(s, name, default)
  if isfield(s, name)
    v = s.(name);
  else
    v = default;
  end
end

function f = field_of(m, su, sl)
% The vector field of the mode pair (su, sl), s = +1/-1 slip on that branch, 0 stuck (a
% smooth upper disc is given su = 1: its law is b_u omega_u on both branches), as one
% anonymous function of its own coefficients (what ode45 calls most):
%
%   alpha'   = omega_u - omega_l
%   omega_u' = (k_m u - k_theta alpha - dT_su - su T_su - (b_u + su db_u) omega_u) / J_u
%   omega_l' = (k_theta alpha - b_l omega_l - sl N(sl omega_l)) / J_l
%
% with sl N(sl w) = sl T_sl + T_1 tanh(w_1 w / 2) + T_2 tanh(w_2 w / 2) (exponential: odd,
% so smooth across w = 0) or sl T_cl + sl (T_sl - T_cl) exp(-|w / omega_s|^delta)
% (stribeck). A stuck disc's coefficients are all 0, so its omega' is exactly 0.
  if su == 0
    u0 = 0;  u1 = 0;  u2 = 0;
  else
    u0 = (m.drive - m.dt_su - su * m.t_su) / m.j_u;
    u1 = m.k / m.j_u;
    u2 = (m.b_u + su * m.db_u) / m.j_u;
  end
  if sl == 0
    l0 = 0;  l1 = 0;  l2 = 0;  c1 = 0;  c2 = 0;
  else
    l1 = m.k / m.j_l;
    l2 = m.b_l / m.j_l;
    if m.stribeck
      l0 = sl * m.t_cl / m.j_l;
      c1 = sl * (m.t_sl - m.t_cl) / m.j_l;
    else
      l0 = sl * m.t_sl / m.j_l;
      c1 = m.t_1 / m.j_l;
      c2 = m.t_2 / m.j_l;
    end
  end
  if m.stribeck
    ws = m.omega_s;
    d = m.delta;
    f = @(t, x) [x(2) - x(3); ...
                 u0 - u1 * x(1) - u2 * x(2); ...
                 l1 * x(1) - l2 * x(3) - l0 - c1 * exp(-abs(x(3) / ws)^d)];
  else
    h1 = m.h_1;
    h2 = m.h_2;
    f = @(t, x) [x(2) - x(3); ...
                 u0 - u1 * x(1) - u2 * x(2); ...
                 l1 * x(1) - l2 * x(3) - l0 - c1 * tanh(h1 * x(3)) - c2 * tanh(h2 * x(3))];
  end
end

function t = applied(m, disc, x)
% T_ex of a disc (1 upper, 2 lower): the torque its friction takes while it sticks.
  if disc == 1
    t = m.drive - m.k * x(1);
  else
    t = m.k * x(1);
  end
end

function s = at_rest(m, disc, x)
% The mode of a disc at omega = 0: 0 (stuck) or the branch it slips on.
  torque = applied(m, disc, x);
  if torque > m.interval(disc, 2)
    s = 1;
  elseif torque < m.interval(disc, 1)
    s = -1;
  else
    s = 0;
  end
end

function [value, terminal, direction] = switching(x, ev)
% The event functions of a mode pair: value = A x + c, one row per event (events_of).
  value = ev.A * x + ev.c;
  terminal = ev.terminal;
  direction = ev.direction;
end

function ev = events_of(m, modes)
% The event functions of the mode pair, each linear in the state, g = A x + c, with its
% tag [disc, kind, side]: kind 1, a slipping disc's omega = 0 (crossed in direction
% -side); kind 2, a stuck disc's T_ex reaching the bound of its interval on that side
% (crossed in direction side).
  ev.A = zeros(0, 3);
  ev.c = zeros(0, 1);
  ev.tags = zeros(0, 3);
  ev.direction = zeros(0, 1);
  for disc = 1:2
    if disc == 1 && m.upper_smooth
      continue
    end
    s = modes(disc);
    if s ~= 0
      row = [0, 0, 0];
      row(1 + disc) = 1;
      ev.A(end + 1, :) = row;
      ev.c(end + 1, 1) = 0;
      ev.tags(end + 1, :) = [disc, 1, s];
      ev.direction(end + 1, 1) = -s;
    else
      for side = [1, -1]
        bound = m.interval(disc, (3 + side) / 2);   % hi for side 1, lo for side -1
        if disc == 1   % k_m u - k_theta alpha - bound
          ev.A(end + 1, :) = [-m.k, 0, 0];
          ev.c(end + 1, 1) = m.drive - bound;
        else           % k_theta alpha - bound
          ev.A(end + 1, :) = [m.k, 0, 0];
          ev.c(end + 1, 1) = -bound;
        end
        ev.tags(end + 1, :) = [disc, 2, side];
        ev.direction(end + 1, 1) = side;
      end
    end
  end
  ev.terminal = ones(size(ev.c));
end

function [te, xe] = refine(f, a, c, ta, xa, tb, opts)
% The root in [ta, tb] of the event g(t) = a x(t) + c, x the solution of x' = f(t, x)
% from x(ta) = xa, to the accuracy of the integration: ode45 across [ta, tb] gives x(tb);
% g is then interpolated by the cubic Hermite polynomial of g and g' = a f at both ends,
%   p(s) = (1 + 2s)(1 - s)^2 g_a + s(1 - s)^2 h g'_a + s^2(3 - 2s) g_b + s^2(s - 1) h g'_b,
% s = (t - ta)/h, h = tb - ta (its error is O(h^4), against O(h^2) for the line through
% g_a and g_b that Octave's event location takes); its root, by Newton's method kept
% inside the bracket, is te, and x(te) comes from ode45 across [ta, te]. Returns te = []
% when g does not change sign over [ta, tb] (then the caller keeps Octave's location).
  te = [];
  xe = [];
  [~, xs] = ode45(f, [ta, tb], xa, opts);
  xb = xs(end, :).';
  h = tb - ta;
  ga = a * xa + c;
  gb = a * xb + c;
  if ga * gb > 0
    return
  end
  da = h * (a * f(ta, xa));
  db = h * (a * f(tb, xb));
  lo = 0;
  hi = 1;
  sn = ga / (ga - gb);   % the linear guess
  for it = 1:50
    p = (1 + 2 * sn) * (1 - sn)^2 * ga + sn * (1 - sn)^2 * da + ...
        sn^2 * (3 - 2 * sn) * gb + sn^2 * (sn - 1) * db;
    if p == 0
      break
    end
    if (p > 0) == (ga > 0)
      lo = sn;
    else
      hi = sn;
    end
    dp = 6 * sn * (sn - 1) * ga + (1 - sn) * (1 - 3 * sn) * da + ...
         6 * sn * (1 - sn) * gb + sn * (3 * sn - 2) * db;
    step = p / dp;
    next = sn - step;
    if ~(next > lo && next < hi)
      next = (lo + hi) / 2;
    end
    if abs(next - sn) <= 1e-15
      sn = next;
      break
    end
    sn = next;
  end
  te = ta + sn * h;
  if te - ta <= 1e-12 * h
    % At ta to rounding: ode45 refuses an empty span.
    te = ta;
    xe = xa;
    return
  end
  [~, xs] = ode45(f, [ta, te], xa, opts);
  xe = xs(end, :).';
end

function [modes, x, found] = switch_at(m, modes, x, tag)
% The switch of the event tag = [disc, kind, side]: a slipping disc reaching
% omega = 0 sticks or reverses; a stuck disc's torque reaching a bound slips that way.
% found = [disc, kind] (kind 1: stick_start, 2: stick_end, 3: reversal).
  disc = tag(1);
  x(1 + disc) = 0;
  if tag(2) == 1
    modes(disc) = at_rest(m, disc, x);
    found = [disc, 1 + 2 * (modes(disc) ~= 0)];
  else
    modes(disc) = tag(3);
    found = [disc, 2];
  end
end

function [modes, x, found] = settle(m, modes, x, switched)
% The mode of the disc that did not switch (switched is the one that did) checked against
% the state at the switch: slipping at or past omega = 0, it is at rest (it sticks or
% reverses); stuck with its torque outside its interval, it slips. found lists [disc,
% kind] of each change (kind 1: stick_start, 2: stick_end, 3: reversal).
  found = zeros(0, 2);
  for disc = 1:2
    if disc == switched || (disc == 1 && m.upper_smooth)
      continue
    end
    s = modes(disc);
    w = x(1 + disc);
    if s ~= 0 && s * w <= 0
      x(1 + disc) = 0;
      new = at_rest(m, disc, x);
      if new == 0
        found(end + 1, :) = [disc, 1];   %#ok<AGROW>
      else
        found(end + 1, :) = [disc, 3];   %#ok<AGROW>
      end
      modes(disc) = new;
    elseif s == 0
      new = at_rest(m, disc, x);
      if new ~= 0
        found(end + 1, :) = [disc, 2];   %#ok<AGROW>
        modes(disc) = new;
      end
    end
  end
end

function [y, events, nseg] = simulate(m, x, grid, tol)
% The solution on the grid (one row per grid time) and the events {t, disc, kind}.
  warning('off', 'integrate_adaptive:unexpected_termination');
  names = {'upper', 'lower'};
  kinds = {'stick_start', 'stick_end', 'reversal'};
  y = zeros(numel(grid), 3);
  events = cell(0, 3);
  t = grid(1);
  t_end = grid(end);
  modes = [1, 1];
  if ~m.upper_smooth
    modes(1) = sign(x(2));
    if x(2) == 0
      modes(1) = at_rest(m, 1, x);
    end
  end
  modes(2) = sign(x(3));
  if x(3) == 0
    modes(2) = at_rest(m, 2, x);
  end
  y(1, :) = x.';
  i = 2;          % the next grid sample to write
  nseg = 0;
  lead = 1e-9;    % the first output after a segment's start (s): see the help text
  plain = odeset('RelTol', tol, 'AbsTol', tol);
  opts = plain;
  while i <= numel(grid)
    nseg = nseg + 1;
    if nseg > 100000
      error('rotor:zeno', 'more than 100000 segments by t = %.17g: Zeno-like switching', t);
    end
    for disc = 1:2
      if modes(disc) == 0
        x(1 + disc) = 0;
      end
    end
    ev = events_of(m, modes);
    opts.Events = @(tt, xx) switching(xx, ev);
    f = field_of(m, modes(1), modes(2));
    if grid(i) - t > 2 * lead
      tspan = [t, t + lead, grid(i:end).'];
      first = 3;
    else
      tspan = [t, grid(i:end).'];
      first = 2;
    end
    if numel(tspan) == 2   % ode45 would return its own steps: ask for the one point
      tspan = [t, (t + grid(i)) / 2, grid(i)];
      first = 3;
    end
    [tt, xx, ~, ~, ie] = ode45(f, tspan, x, opts);
    done = tt(end) >= t_end;
    if done
      keep = first:numel(tt);
    else
      keep = first:numel(tt) - 1;   % the last row is the event
    end
    n = numel(keep);
    y(i:i + n - 1, :) = xx(keep, :);
    for disc = 1:2
      if modes(disc) == 0
        y(i:i + n - 1, 1 + disc) = 0;
      end
    end
    i = i + n;
    if done
      break
    end
    % The event, located again between the last output before it and the output time
    % after it, where Octave found the sign change.
    k = ie(end);
    [t, x] = refine(f, ev.A(k, :), ev.c(k), tt(end - 1), xx(end - 1, :).', ...
                    tspan(numel(tt)), plain);
    if isempty(t)
      t = tt(end);
      x = xx(end, :).';
    end
    % The switch the event function located, then any other at the same instant (a disc
    % at or past omega = 0, a stuck disc outside its interval).
    [modes, x, found] = switch_at(m, modes, x, ev.tags(k, :));
    [modes, x, more] = settle(m, modes, x, found(1));
    found = [found; more];   %#ok<AGROW>
    for k = 1:size(found, 1)
      events(end + 1, :) = {t, names{found(k, 1)}, kinds{found(k, 2)}};   %#ok<AGROW>
    end
    % A grid time the event fell on is the event's state.
    if i <= numel(grid) && grid(i) <= t
      y(i, :) = x.';
      i = i + 1;
    end
  end
end

function g = grid_times(dt, t_end)
% The output grid 0, dt, 2 dt, ... ending exactly at t_end (as rotor-model's OutputGrid):
% the last multiple of dt is t_end when within 1e-9 dt of it, else t_end is appended.
  n = floor((t_end / dt) * (1 + 1e-12) + 1e-9);
  g = (0:n).' * dt;
  if abs(g(end) - t_end) <= 1e-9 * dt
    g(end) = t_end;
  else
    g(end + 1) = t_end;
  end
end

function write_trace(path, grid, y)
  fid = fopen(path, 'w');
  if fid < 0
    error('rotor:write', '%s: cannot write the trace', path);
  end
  fprintf(fid, 't,alpha,omega_u,omega_l\n');
  fprintf(fid, '%.17g,%.17g,%.17g,%.17g\n', [grid, y].');
  fclose(fid);
end

function write_events(path, events)
  fid = fopen(path, 'w');
  if fid < 0
    error('rotor:write', '%s: cannot write the events', path);
  end
  fprintf(fid, 't,disc,kind\n');
  for k = 1:size(events, 1)
    fprintf(fid, '%.17g,%s,%s\n', events{k, 1}, events{k, 2}, events{k, 3});
  end
  fclose(fid);
end
