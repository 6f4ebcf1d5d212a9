--
-- PostgreSQL database dump
--


-- Dumped from database version 15.18 (Debian 15.18-0+deb12u1)
-- Dumped by pg_dump version 15.18 (Debian 15.18-0+deb12u1)

SET statement_timeout = 0;
SET lock_timeout = 0;
SET idle_in_transaction_session_timeout = 0;
SET client_encoding = 'UTF8';
SET standard_conforming_strings = on;
SELECT pg_catalog.set_config('search_path', '', false);
SET check_function_bodies = false;
SET xmloption = content;
SET client_min_messages = warning;
SET row_security = off;

--
-- Name: public; Type: SCHEMA; Schema: -; Owner: -
--

-- *not* creating schema, since initdb creates it


SET default_tablespace = '';

SET default_table_access_method = heap;

--
-- Name: audit; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.audit (
    id integer NOT NULL,
    at timestamp with time zone NOT NULL,
    user_id integer,
    user_name character varying(64),
    action character varying(32) NOT NULL,
    target character varying(255) NOT NULL,
    detail text NOT NULL,
    client character varying(64) NOT NULL
);


--
-- Name: audit_id_seq; Type: SEQUENCE; Schema: public; Owner: -
--

CREATE SEQUENCE public.audit_id_seq
    AS integer
    START WITH 1
    INCREMENT BY 1
    NO MINVALUE
    NO MAXVALUE
    CACHE 1;


--
-- Name: audit_id_seq; Type: SEQUENCE OWNED BY; Schema: public; Owner: -
--

ALTER SEQUENCE public.audit_id_seq OWNED BY public.audit.id;


--
-- Name: interval_decisions; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.interval_decisions (
    id integer NOT NULL,
    run_id character varying(32),
    interval_id integer NOT NULL,
    decision character varying(16) NOT NULL,
    note text NOT NULL,
    reviewer character varying(255) NOT NULL,
    client character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL
);


--
-- Name: interval_decisions_id_seq; Type: SEQUENCE; Schema: public; Owner: -
--

CREATE SEQUENCE public.interval_decisions_id_seq
    AS integer
    START WITH 1
    INCREMENT BY 1
    NO MINVALUE
    NO MAXVALUE
    CACHE 1;


--
-- Name: interval_decisions_id_seq; Type: SEQUENCE OWNED BY; Schema: public; Owner: -
--

ALTER SEQUENCE public.interval_decisions_id_seq OWNED BY public.interval_decisions.id;


--
-- Name: reviews; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.reviews (
    id integer NOT NULL,
    take_id character varying(32),
    status character varying(16) NOT NULL,
    notes text NOT NULL,
    reviewer character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL,
    user_id integer
);


--
-- Name: reviews_id_seq; Type: SEQUENCE; Schema: public; Owner: -
--

CREATE SEQUENCE public.reviews_id_seq
    AS integer
    START WITH 1
    INCREMENT BY 1
    NO MINVALUE
    NO MAXVALUE
    CACHE 1;


--
-- Name: reviews_id_seq; Type: SEQUENCE OWNED BY; Schema: public; Owner: -
--

ALTER SEQUENCE public.reviews_id_seq OWNED BY public.reviews.id;


--
-- Name: runs; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.runs (
    id character varying(32) NOT NULL,
    take_id character varying(32),
    status character varying(16) NOT NULL,
    progress integer NOT NULL,
    step character varying(255) NOT NULL,
    options json NOT NULL,
    input_sha256 character varying(64) NOT NULL,
    version character varying(32) NOT NULL,
    error text,
    summary json,
    server_time_s double precision,
    created_at timestamp with time zone NOT NULL,
    started_at timestamp with time zone,
    finished_at timestamp with time zone,
    attempts integer DEFAULT 0 NOT NULL
);


--
-- Name: shoots; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.shoots (
    id character varying(32) NOT NULL,
    name character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL
);


--
-- Name: source_hashes; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.source_hashes (
    path character varying(1024) NOT NULL,
    size_bytes bigint NOT NULL,
    mtime_ns bigint NOT NULL,
    sha256 character varying(64) NOT NULL
);


--
-- Name: take_qa; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.take_qa (
    take_id character varying(32) NOT NULL,
    shoot_id character varying(32),
    name character varying(255) NOT NULL,
    kind character varying(16) NOT NULL,
    created_at timestamp with time zone NOT NULL,
    run_id character varying(32),
    status character varying(16),
    review_status character varying(16) NOT NULL,
    reviewer character varying(255),
    score double precision,
    n_frames integer,
    duration_s double precision,
    rig character varying(64),
    twist_intervals integer,
    corrected_joint_frames integer,
    violation_share double precision,
    worst_joint character varying(255),
    filter_residual_mm double precision,
    missing_share double precision,
    n_findings integer,
    joint_violations json
);


--
-- Name: takes; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.takes (
    id character varying(32) NOT NULL,
    name character varying(255) NOT NULL,
    format character varying(32) NOT NULL,
    kind character varying(16) NOT NULL,
    size_bytes bigint NOT NULL,
    sha256 character varying(64) NOT NULL,
    n_frames integer NOT NULL,
    fps double precision NOT NULL,
    n_joints integer NOT NULL,
    file_name character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL,
    owner_id integer,
    shoot_id character varying(32)
);


--
-- Name: tokens; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.tokens (
    id character varying(32) NOT NULL,
    user_id integer,
    kind character varying(16) NOT NULL,
    name character varying(255) NOT NULL,
    secret_sha256 character varying(64) NOT NULL,
    csrf character varying(64),
    created_at timestamp with time zone NOT NULL,
    expires_at timestamp with time zone NOT NULL,
    last_used_at timestamp with time zone,
    revoked_at timestamp with time zone
);


--
-- Name: users; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.users (
    id integer NOT NULL,
    name character varying(64) NOT NULL,
    role character varying(16) NOT NULL,
    password_hash text,
    disabled boolean NOT NULL,
    created_at timestamp with time zone NOT NULL
);


--
-- Name: users_id_seq; Type: SEQUENCE; Schema: public; Owner: -
--

CREATE SEQUENCE public.users_id_seq
    AS integer
    START WITH 1
    INCREMENT BY 1
    NO MINVALUE
    NO MAXVALUE
    CACHE 1;


--
-- Name: users_id_seq; Type: SEQUENCE OWNED BY; Schema: public; Owner: -
--

ALTER SEQUENCE public.users_id_seq OWNED BY public.users.id;


--
-- Name: audit id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.audit ALTER COLUMN id SET DEFAULT nextval('public.audit_id_seq'::regclass);


--
-- Name: interval_decisions id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.interval_decisions ALTER COLUMN id SET DEFAULT nextval('public.interval_decisions_id_seq'::regclass);


--
-- Name: reviews id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews ALTER COLUMN id SET DEFAULT nextval('public.reviews_id_seq'::regclass);


--
-- Name: users id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.users ALTER COLUMN id SET DEFAULT nextval('public.users_id_seq'::regclass);


--
-- Data for Name: audit; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: interval_decisions; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: reviews; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.reviews VALUES (1, 'df0d204a381d4db8ade18382dbcdbee4', 'needs_fix', 'left leg pops', 'ann', '2026-12-01 23:34:29.093714+00', NULL);
INSERT INTO public.reviews VALUES (2, 'df0d204a381d4db8ade18382dbcdbee4', 'approved', 'fixed', 'bo', '2026-12-01 23:34:29.199477+00', NULL);


--
-- Data for Name: runs; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.runs VALUES ('3face0d21b904643aa76512f48336c2c', 'df0d204a381d4db8ade18382dbcdbee4', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000}', 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', '0.1.0', NULL, '{"n_frames": 24, "fps": 30.000030000029998, "duration_s": 0.7999992, "n_joints": 18, "length_unit": "unknown", "n_findings": 0, "findings_by_kind": {}, "steps": {"twist": "done", "limits": "no_model", "filter": "skipped"}}', 0.9973271519993432, '2026-12-01 23:34:27.296829+00', '2026-12-01 23:34:27.365495+00', '2026-12-01 23:34:28.338121+00', 0);
INSERT INTO public.runs VALUES ('14138e27cc1a470c933ffd1b1bec5fad', '14038e93f1224201910feeb6df75c539', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000}', 'dd6988f41b55162ee97efcb900f10d254734a5987b80534a80c7cec5406f228a', '0.1.0', NULL, '{"n_frames": 25, "fps": 30.000030000029998, "duration_s": 0.8333325, "n_joints": 18, "length_unit": "unknown", "n_findings": 0, "findings_by_kind": {}, "steps": {"twist": "done", "limits": "no_model", "filter": "skipped"}}', 0.20353359700129658, '2026-12-01 23:34:28.426951+00', '2026-12-01 23:34:28.459636+00', '2026-12-01 23:34:28.655639+00', 0);
INSERT INTO public.runs VALUES ('4bb818be207e411db0c60c6c038faffa', 'df0d204a381d4db8ade18382dbcdbee4', 'done', 100, 'done', '{"checks": ["limits"], "twist_method": "robust", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000}', 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', '0.1.0', NULL, '{"n_frames": 24, "fps": 30.000030000029998, "duration_s": 0.7999992, "n_joints": 18, "length_unit": "unknown", "n_findings": 0, "findings_by_kind": {}, "steps": {"twist": "skipped", "limits": "no_model", "filter": "skipped"}}', 0.14524893099951441, '2026-12-01 23:34:28.787522+00', '2026-12-01 23:34:28.812332+00', '2026-12-01 23:34:28.957698+00', 0);


--
-- Data for Name: shoots; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: source_hashes; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: take_qa; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.take_qa VALUES ('df0d204a381d4db8ade18382dbcdbee4', NULL, 'walk_a.bvh', 'motion', '2026-12-01 23:34:27.291627+00', '4bb818be207e411db0c60c6c038faffa', 'done', 'approved', 'bo', NULL, 24, 0.7999992, NULL, NULL, NULL, NULL, NULL, NULL, NULL, 0, 'null');
INSERT INTO public.take_qa VALUES ('14038e93f1224201910feeb6df75c539', NULL, 'walk_b.bvh', 'motion', '2026-12-01 23:34:28.425515+00', '14138e27cc1a470c933ffd1b1bec5fad', 'done', 'unreviewed', NULL, NULL, 25, 0.8333325, NULL, NULL, NULL, NULL, NULL, NULL, NULL, 0, 'null');


--
-- Data for Name: takes; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.takes VALUES ('df0d204a381d4db8ade18382dbcdbee4', 'walk_a.bvh', 'bvh', 'motion', 12142, 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', 24, 30.000030000029998, 18, 'walk_a.bvh', '2026-12-01 23:34:27.291627+00', NULL, NULL);
INSERT INTO public.takes VALUES ('14038e93f1224201910feeb6df75c539', 'walk_b.bvh', 'bvh', 'motion', 12633, 'dd6988f41b55162ee97efcb900f10d254734a5987b80534a80c7cec5406f228a', 25, 30.000030000029998, 18, 'walk_b.bvh', '2026-12-01 23:34:28.425515+00', NULL, NULL);


--
-- Data for Name: tokens; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Data for Name: users; Type: TABLE DATA; Schema: public; Owner: -
--



--
-- Name: audit_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.audit_id_seq', 1, false);


--
-- Name: interval_decisions_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.interval_decisions_id_seq', 1, false);


--
-- Name: reviews_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.reviews_id_seq', 2, true);


--
-- Name: users_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.users_id_seq', 1, false);


--
-- Name: audit audit_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.audit
    ADD CONSTRAINT audit_pkey PRIMARY KEY (id);


--
-- Name: interval_decisions interval_decisions_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.interval_decisions
    ADD CONSTRAINT interval_decisions_pkey PRIMARY KEY (id);


--
-- Name: reviews reviews_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews
    ADD CONSTRAINT reviews_pkey PRIMARY KEY (id);


--
-- Name: runs runs_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.runs
    ADD CONSTRAINT runs_pkey PRIMARY KEY (id);


--
-- Name: shoots shoots_name_key; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.shoots
    ADD CONSTRAINT shoots_name_key UNIQUE (name);


--
-- Name: shoots shoots_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.shoots
    ADD CONSTRAINT shoots_pkey PRIMARY KEY (id);


--
-- Name: source_hashes source_hashes_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.source_hashes
    ADD CONSTRAINT source_hashes_pkey PRIMARY KEY (path);


--
-- Name: take_qa take_qa_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.take_qa
    ADD CONSTRAINT take_qa_pkey PRIMARY KEY (take_id);


--
-- Name: takes takes_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.takes
    ADD CONSTRAINT takes_pkey PRIMARY KEY (id);


--
-- Name: tokens tokens_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.tokens
    ADD CONSTRAINT tokens_pkey PRIMARY KEY (id);


--
-- Name: users users_name_key; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.users
    ADD CONSTRAINT users_name_key UNIQUE (name);


--
-- Name: users users_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.users
    ADD CONSTRAINT users_pkey PRIMARY KEY (id);


--
-- Name: ix_audit_at; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_audit_at ON public.audit USING btree (at);


--
-- Name: ix_interval_decisions_run_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_interval_decisions_run_id ON public.interval_decisions USING btree (run_id);


--
-- Name: ix_reviews_take_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_reviews_take_id ON public.reviews USING btree (take_id);


--
-- Name: ix_runs_status; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_runs_status ON public.runs USING btree (status);


--
-- Name: ix_runs_take_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_runs_take_id ON public.runs USING btree (take_id);


--
-- Name: ix_take_qa_shoot_created; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_created ON public.take_qa USING btree (shoot_id, created_at);


--
-- Name: ix_take_qa_shoot_name; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_name ON public.take_qa USING btree (shoot_id, name);


--
-- Name: ix_take_qa_shoot_review; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_review ON public.take_qa USING btree (shoot_id, review_status);


--
-- Name: ix_take_qa_shoot_score; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_score ON public.take_qa USING btree (shoot_id, score);


--
-- Name: ix_take_qa_shoot_status; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_take_qa_shoot_status ON public.take_qa USING btree (shoot_id, status);


--
-- Name: ix_takes_shoot_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_takes_shoot_id ON public.takes USING btree (shoot_id);


--
-- Name: ix_tokens_user_id; Type: INDEX; Schema: public; Owner: -
--

CREATE INDEX ix_tokens_user_id ON public.tokens USING btree (user_id);


--
-- Name: interval_decisions interval_decisions_run_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.interval_decisions
    ADD CONSTRAINT interval_decisions_run_id_fkey FOREIGN KEY (run_id) REFERENCES public.runs(id) ON DELETE CASCADE;


--
-- Name: reviews reviews_take_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews
    ADD CONSTRAINT reviews_take_id_fkey FOREIGN KEY (take_id) REFERENCES public.takes(id) ON DELETE CASCADE;


--
-- Name: runs runs_take_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.runs
    ADD CONSTRAINT runs_take_id_fkey FOREIGN KEY (take_id) REFERENCES public.takes(id) ON DELETE CASCADE;


--
-- Name: take_qa take_qa_take_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.take_qa
    ADD CONSTRAINT take_qa_take_id_fkey FOREIGN KEY (take_id) REFERENCES public.takes(id) ON DELETE CASCADE;


--
-- Name: takes takes_shoot_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.takes
    ADD CONSTRAINT takes_shoot_id_fkey FOREIGN KEY (shoot_id) REFERENCES public.shoots(id);


--
-- Name: tokens tokens_user_id_fkey; Type: FK CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.tokens
    ADD CONSTRAINT tokens_user_id_fkey FOREIGN KEY (user_id) REFERENCES public.users(id) ON DELETE CASCADE;


--
-- PostgreSQL database dump complete
--


