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
-- Name: reviews; Type: TABLE; Schema: public; Owner: -
--

CREATE TABLE public.reviews (
    id integer NOT NULL,
    take_id character varying(32),
    status character varying(16) NOT NULL,
    notes text NOT NULL,
    reviewer character varying(255) NOT NULL,
    created_at timestamp with time zone NOT NULL
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
    finished_at timestamp with time zone
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
    created_at timestamp with time zone NOT NULL
);


--
-- Name: reviews id; Type: DEFAULT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.reviews ALTER COLUMN id SET DEFAULT nextval('public.reviews_id_seq'::regclass);


--
-- Data for Name: reviews; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.reviews VALUES (1, 'df0d204a381d4db8ade18382dbcdbee4', 'needs_fix', 'left leg pops', 'ann', '2026-12-01 23:34:29.093714+00');
INSERT INTO public.reviews VALUES (2, 'df0d204a381d4db8ade18382dbcdbee4', 'approved', 'fixed', 'bo', '2026-12-01 23:34:29.199477+00');


--
-- Data for Name: runs; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.runs VALUES ('3face0d21b904643aa76512f48336c2c', 'df0d204a381d4db8ade18382dbcdbee4', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000}', 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', '0.1.0', NULL, '{"n_frames": 24, "fps": 30.000030000029998, "duration_s": 0.7999992, "n_joints": 18, "length_unit": "unknown", "n_findings": 0, "findings_by_kind": {}, "steps": {"twist": "done", "limits": "no_model", "filter": "skipped"}}', 0.9973271519993432, '2026-12-01 23:34:27.296829+00', '2026-12-01 23:34:27.365495+00', '2026-12-01 23:34:28.338121+00');
INSERT INTO public.runs VALUES ('14138e27cc1a470c933ffd1b1bec5fad', '14038e93f1224201910feeb6df75c539', 'done', 100, 'done', '{"checks": ["twist", "limits", "filter"], "twist_method": "robust", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000}', 'dd6988f41b55162ee97efcb900f10d254734a5987b80534a80c7cec5406f228a', '0.1.0', NULL, '{"n_frames": 25, "fps": 30.000030000029998, "duration_s": 0.8333325, "n_joints": 18, "length_unit": "unknown", "n_findings": 0, "findings_by_kind": {}, "steps": {"twist": "done", "limits": "no_model", "filter": "skipped"}}', 0.20353359700129658, '2026-12-01 23:34:28.426951+00', '2026-12-01 23:34:28.459636+00', '2026-12-01 23:34:28.655639+00');
INSERT INTO public.runs VALUES ('4bb818be207e411db0c60c6c038faffa', 'df0d204a381d4db8ade18382dbcdbee4', 'done', 100, 'done', '{"checks": ["limits"], "twist_method": "robust", "filter_method": null, "filter_preset": null, "filter_params": {}, "max_points": 2000}', 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', '0.1.0', NULL, '{"n_frames": 24, "fps": 30.000030000029998, "duration_s": 0.7999992, "n_joints": 18, "length_unit": "unknown", "n_findings": 0, "findings_by_kind": {}, "steps": {"twist": "skipped", "limits": "no_model", "filter": "skipped"}}', 0.14524893099951441, '2026-12-01 23:34:28.787522+00', '2026-12-01 23:34:28.812332+00', '2026-12-01 23:34:28.957698+00');


--
-- Data for Name: takes; Type: TABLE DATA; Schema: public; Owner: -
--

INSERT INTO public.takes VALUES ('df0d204a381d4db8ade18382dbcdbee4', 'walk_a.bvh', 'bvh', 'motion', 12142, 'bc105caaff9beb22ad067d2e4764c349af7748669b4e2d66b8dde1e5392f4896', 24, 30.000030000029998, 18, 'walk_a.bvh', '2026-12-01 23:34:27.291627+00');
INSERT INTO public.takes VALUES ('14038e93f1224201910feeb6df75c539', 'walk_b.bvh', 'bvh', 'motion', 12633, 'dd6988f41b55162ee97efcb900f10d254734a5987b80534a80c7cec5406f228a', 25, 30.000030000029998, 18, 'walk_b.bvh', '2026-12-01 23:34:28.425515+00');


--
-- Name: reviews_id_seq; Type: SEQUENCE SET; Schema: public; Owner: -
--

SELECT pg_catalog.setval('public.reviews_id_seq', 2, true);


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
-- Name: takes takes_pkey; Type: CONSTRAINT; Schema: public; Owner: -
--

ALTER TABLE ONLY public.takes
    ADD CONSTRAINT takes_pkey PRIMARY KEY (id);


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
-- PostgreSQL database dump complete
--


